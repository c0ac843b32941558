"""The physics kit: fields, energies, one assembler and the atlas quadrature they share.

Physics on an atlas is an energy over declared fields (issue 17; in the spirit of
scikit-fem's forms and one ``asm``): a physics plugin declares its :class:`~.fields.Field`
objects and writes a pointwise energy kernel of their local jets
(:mod:`pointatlas_kit.energy`); :mod:`pointatlas_kit.assembler` turns it into the global
energy, residual and sparse tangent on an :class:`~.atlas_quadrature.AtlasQuadrature`.
Nothing here imports a physics plugin.
"""
