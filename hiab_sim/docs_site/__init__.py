"""Pages of the documentation site generated from the code: file formats, result schema, CLI, test catalogue."""
