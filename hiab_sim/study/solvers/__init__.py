"""Solvers of the NLP: SLSQP with checkpoints and starts, IPOPT through CasADi, the feasibility phase."""
