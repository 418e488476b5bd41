"""A study file read into frozen dataclasses: the study, its tasks, payloads, energy and build settings."""
