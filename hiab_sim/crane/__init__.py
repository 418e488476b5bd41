"""The crane: closed-chain mechanism math and forward kinematics (numpy only)."""
