"""The NLP's constraint blocks: the registry, the built-in rows, and the thermal, brake, mounting and structure rows."""
