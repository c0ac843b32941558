"""pointatlas built-in approximants plugins."""
