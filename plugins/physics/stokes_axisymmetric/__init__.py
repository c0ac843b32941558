"""Axisymmetric Stokes boundary elements: ring kernels, generating curves, self-propulsion."""
