"""The crane: its description (dataclasses), YAML loader, closed-chain mechanism math and forward kinematics."""
