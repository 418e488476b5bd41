"""Controllers that drive the closed-loop crane environment (:mod:`hiab_sim.env`)."""

from hiab_sim.control.cascade import CascadeController, CascadeGains

__all__ = ["CascadeController", "CascadeGains"]
