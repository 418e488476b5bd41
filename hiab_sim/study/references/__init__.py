"""What the TCP must do in a task: reference kinds (spiral, pick and place) and trajectory files."""
