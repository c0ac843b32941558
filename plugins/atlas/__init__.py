"""The atlas of a point-set manifold: partition, charts, partition of unity, quadrature (thesis §3)."""
