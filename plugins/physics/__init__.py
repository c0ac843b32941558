"""pointatlas built-in physics plugins."""
