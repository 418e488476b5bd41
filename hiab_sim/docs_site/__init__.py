"""Pages of the documentation site generated from the code and from recorded runs (the results pages)."""
