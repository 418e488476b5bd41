"""The MJCF crane model, regenerated per link-length set."""

from hiab_sim.model.mjcf import build_model, build_spec, to_xml

__all__ = ["build_model", "build_spec", "to_xml"]
