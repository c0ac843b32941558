"""The ``laplace_beltrami`` physics plugin: −Δ_Γ u + c u = f on a point-set surface."""
