"""Structural checks of a mounting: screw buckling, pin loads and the drive train's natural frequencies."""
