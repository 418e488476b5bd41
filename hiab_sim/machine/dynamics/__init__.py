"""Inverse dynamics of any machine: MjSpec model, MuJoCo and planar Newton-Euler paths, pin and soil forces."""
