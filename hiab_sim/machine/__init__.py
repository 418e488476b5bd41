"""Any planar parallel-serial machine: description, loader, loop closure and kinematics."""
