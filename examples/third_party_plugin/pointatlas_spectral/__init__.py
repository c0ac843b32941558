"""An example third-party pointatlas plugin (see the README's plugin guide)."""
