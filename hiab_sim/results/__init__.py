"""Results of a run: the typed ``result.json`` schema, its JSON codec and the one reader of a result folder."""
