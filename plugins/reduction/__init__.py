"""Lagrangian model reduction on slow manifolds learnt from snapshots (thesis §5)."""
