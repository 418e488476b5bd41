"""Kinematics of a machine: loop closure (closed form, numeric), forward kinematics, assembly, design partials."""
