"""Shared pieces of the fracture-path tests: the small centre-cracked plate and a kill -9
after the n-th durable write of ``increments.nc``."""
import pytest

#: a full plate [-0.5, 0.5]², 21 × 21 points (spacing 0.05), κ̄ = 0.1 (2 spacings), a crack
#: of 2a = 0.4 across the centre, the bottom edge held, the top pulled to 0.055 in five
#: steps: the crack grows stably from 0.033 on (the reaction peaks at 0.044), the last step
#: is a jump (~60-100 staggered iterations); about 35 s a run
CENTRE_CRACKED_PLATE = [
    "experiment=fracture_griffith", "source.model=full", "source.n_points=441",
    "physics.length_scale=0.1", "physics.precracks=[{polyline: [[-0.2, 0, 0], [0.2, 0, 0]]}]",
    "physics.supports=[{kind: fixed, components: [1, 2], where: {plane: [0, 1, 0, -0.5]}},"
    " {kind: displacement, value: [0, 0.1, 0], where: {plane: [0, 1, 0, 0.5]}}]",
    "study.n_increments=5", "study.max_factor=0.55", "study.jump_fraction=0.5",
    "study.griffith_half_length=null", "study.min_step_fraction=0.125"]


@pytest.fixture(scope="session")
def run_plate():
    """run(run_dir, *overrides): study=fracture on :data:`CENTRE_CRACKED_PLATE` in process,
    its results Dataset."""
    from pointatlas.testing import composed_context

    def run(run_dir, *overrides):
        ctx = composed_context(run_dir, [*CENTRE_CRACKED_PLATE, *overrides])
        return ctx.plugin("study").run(ctx)

    return run


class Killed(BaseException):
    """What a kill -9 leaves: the process stops right after a write, nothing else runs."""


@pytest.fixture
def interrupt_fracture(monkeypatch):
    """interrupt(run, after): call ``run()`` with every write of increments.nc followed by a
    kill once it holds ``after`` increments (None: at the first write); the kill is checked
    to happen, and the real writer is restored."""
    import pointatlas_studies.fracture_increments as store

    def interrupt(run, after=None):
        real = store.write

        def write_then_die(path, problem, records, step, settings):
            real(path, problem, records, step, settings)
            if after is None or len(records) == after:
                raise Killed

        monkeypatch.setattr(store, "write", write_then_die)
        try:
            with pytest.raises(Killed):
                run()
        finally:
            monkeypatch.setattr(store, "write", real)

    return interrupt


@pytest.fixture(scope="session")
def paraview_series():
    """read(pvd): the steps of a ParaView collection as [(timestep, pyvista mesh)], after
    checking what ParaView needs: a Collection whose files exist (relative to the .pvd),
    named increment_0000, 0001, … in order, timesteps increasing strictly and those pyvista's
    PVD reader reports; every step a triangulated surface over all its points."""
    import xml.etree.ElementTree as ET
    from pathlib import Path

    import numpy as np
    import pyvista as pv

    def read(pvd):
        pvd = Path(pvd)
        root = ET.parse(pvd).getroot()
        assert root.tag == "VTKFile" and root.get("type") == "Collection"
        steps = root.find("Collection").findall("DataSet")
        files = [s.get("file") for s in steps]
        assert files == [f"snapshots/increment_{k:04d}.vtp" for k in range(len(steps))]
        times = [float(s.get("timestep")) for s in steps]
        assert len(steps) and np.all(np.diff(times) > 0)
        assert pv.get_reader(str(pvd)).time_values == times
        out = []
        for t, f in zip(times, files):
            mesh = pv.read(pvd.parent / f)
            tri = np.asarray(mesh.GetPolys().GetConnectivityArray()).reshape(-1, 3)
            assert len(tri) and np.unique(tri).size == mesh.n_points
            out.append((t, mesh))
        return out

    return read
