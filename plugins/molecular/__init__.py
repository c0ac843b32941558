"""Molecular collective variables on learnt manifolds (SandCV) and adaptive biasing force
on OpenMM (Hashemian, Millán & Arroyo, J. Chem. Phys. 139 (2013) 214101)."""
