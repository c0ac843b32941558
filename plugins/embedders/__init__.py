"""pointatlas built-in embedders plugins."""
