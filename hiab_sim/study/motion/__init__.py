"""B-spline joint trajectories, planar TCP kinematics and inverse kinematics of the reference."""
