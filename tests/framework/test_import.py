"""`import pointatlas` stays light: no pyvista, matplotlib, numba (nor xarray) at import."""
import subprocess
import sys


def test_import_pulls_in_no_heavy_module():
    code = ("import sys, pointatlas; heavy = [m for m in ('pyvista', 'matplotlib', 'numba', "
            "'xarray', 'vtk', 'sklearn') if m in sys.modules]; print(heavy)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
