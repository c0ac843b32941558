"""The shell's one kit field: the displacement of the middle surface (light to import)."""
from pointatlas_kit.fields import Field

#: 3 Cartesian components, chart derivatives to order 2; the energy uses derivatives only
DISPLACEMENT = Field("displacement", components=3, order=2, value=False, units="length",
                     long_name="displacement of the middle surface")
