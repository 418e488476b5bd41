"""Import of an MJCF with closed loops into a machine description, and its round-trip check."""
