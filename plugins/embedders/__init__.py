"""pointatlas built-in embedders plugins.

Plugins (entry points ``pointatlas.embedders``): ``pca``, ``isomap``, ``lle``, ``mlle``, ``nlie``.
Shared pieces: ``neighbor_graph`` (k-NN / radius graphs, connectivity), ``geodesics`` (graph
shortest paths), ``mds`` (classical and landmark MDS), ``aic`` (affine isometric correction,
thesis Appendix E.1), ``quality`` (stress E_S, trustworthiness, residual variance,
reconstruction error), ``intrinsic_dimension`` (thesis §2.3), ``nlie_stress`` / ``newton_cg``
(NLIE energy, derivatives and optimiser, thesis Appendix C), ``out_of_sample`` (the extensions
behind ``transform``). Every embedder is a scikit-learn transformer (``base.EmbedderBase``).
"""
