"""The NLP: its interface, constraint blocks, objectives, the single-task and mix problems, ID partials."""
