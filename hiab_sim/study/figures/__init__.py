"""Figures of a result: optimisation history, designs, energy and cross-evaluation."""
