"""Plane-strain neo-Hookean elastodynamics on linear triangles: the full model of issue 21."""
