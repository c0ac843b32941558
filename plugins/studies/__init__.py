"""pointatlas built-in studies plugins."""
