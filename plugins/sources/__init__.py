"""pointatlas built-in sources plugins."""
