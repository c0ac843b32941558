"""A nonlinear shell path interrupted after two increments and resumed gives the results of
the uninterrupted path: every increment, every variable, fields within 1e-8 and the same
headline metric, under force control and under arc-length control (issue 15, defect 1);
increments.nc survives an interrupted write and its leftovers are removed (defect 2); a
resume from a missing or unusable directory is one clear error."""
import numpy as np
import pytest
import xarray as xr

import pointatlas_studies.increment_store as store
from pointatlas.errors import ConfigError, InputError
from pointatlas.testing import composed_context

# the open hemisphere at 200 points, three increments to λ = 0.05 (the first tabulated level
# of Sze et al., so max_relative_error is defined)
SMALL = ["experiment=shell_open_hemisphere", "source.n_points=200", "study.quadrature_order=3",
         "study.n_increments=3", "study.max_load_factor=0.05"]
#: wall-clock variables, the only ones a resumed run may not repeat
WALL_TIME = {"increment_time", "time_per_newton_iteration"}
#: the ParaView collection of the path's snapshots/increment_NNNN.vtp
PVD = "shell_nonlinear.pvd"


class Killed(BaseException):
    """What a kill -9 leaves: the process stops right after a write, nothing else runs."""


def _run(run_dir, *overrides):
    ctx = composed_context(run_dir, [*SMALL, *overrides])
    return ctx.plugin("study").run(ctx)


def _run_killed_after(monkeypatch, run_dir, n, *overrides):
    """Run until increments.nc holds ``n`` increments, then stop as a kill would."""
    real = store.write_increments

    def write_then_die(path, ds, records, settings):
        real(path, ds, records, settings)
        if len(records) == n:
            raise Killed

    monkeypatch.setattr(store, "write_increments", write_then_die)
    with pytest.raises(Killed):
        _run(run_dir, *overrides)
    monkeypatch.setattr(store, "write_increments", real)
    with xr.open_dataset(run_dir / "increments.nc") as saved:
        assert saved.sizes["increment"] == n


def _run_keeping_increments_after(monkeypatch, run_dir, n, saved_dir, *overrides):
    """Run the whole path; ``saved_dir`` gets increments.nc as it was on disk right after
    the write of increment ``n`` (what a kill -9 at that moment leaves)."""
    import shutil

    real = store.write_increments

    def write_and_keep(path, ds, records, settings):
        real(path, ds, records, settings)
        if len(records) == n:
            saved_dir.mkdir(parents=True)
            shutil.copy2(path, saved_dir / path.name)
            # and the ParaView series as it is then (increment n's .vtp comes next)
            shutil.copytree(path.parent / "snapshots", saved_dir / "snapshots")
            shutil.copy2(path.parent / PVD, saved_dir / PVD)

    monkeypatch.setattr(store, "write_increments", write_and_keep)
    try:
        return _run(run_dir, *overrides)
    finally:
        monkeypatch.setattr(store, "write_increments", real)


def _assert_same_results(resumed, full):
    assert resumed.sizes == full.sizes
    assert set(resumed.variables) == set(full.variables)
    # within 1e-8 of each variable's scale (at least 1), load factors included
    for name, var in full.variables.items():
        if name in WALL_TIME or var.dtype.kind not in "biuf":
            continue
        scale = max(float(np.nanmax(np.abs(var.values), initial=0.0)), 1.0)
        np.testing.assert_allclose(resumed[name].values, var.values, rtol=0, atol=1e-8 * scale,
                                   err_msg=name)
    assert float(resumed["max_relative_error"]) == pytest.approx(
        float(full["max_relative_error"]), abs=1e-8)


@pytest.mark.parametrize("control", ["force", "arc_length"])
def test_a_resumed_path_gives_the_uninterrupted_results(tmp_path, monkeypatch, control,
                                                        paraview_series):
    extra = [f"study.control={control}"]
    full = _run_keeping_increments_after(monkeypatch, tmp_path / "full", 2, tmp_path / "killed",
                                         *extra)
    assert full.sizes["increment"] == 3 and "reaction" in full
    assert np.isfinite(float(full["max_relative_error"]))
    resumed = _run(tmp_path / "resumed", *extra, f"study.resume_from={tmp_path / 'killed'}")
    _assert_same_results(resumed, full)
    _assert_same_series(paraview_series, tmp_path, full, control)
    # the resumed run's own increments.nc holds the whole path too (it can be resumed again)
    with xr.open_dataset(tmp_path / "resumed" / "increments.nc") as inc:
        assert inc.sizes["increment"] == full.sizes["increment"]


def _assert_same_series(read, tmp_path, full, control):
    """The killed run's .pvd lists the increments whose .vtp were complete (the kill came
    after increments.nc held 2, before the second .vtp); the resumed run's series is the
    uninterrupted one's: the same .pvd, the same arrays."""
    killed = read(tmp_path / "killed" / PVD)
    assert len(killed) == 1
    assert [p.name for p in (tmp_path / "killed" / "snapshots").iterdir()] == \
        ["increment_0000.vtp"]
    a, b = read(tmp_path / "full" / PVD), read(tmp_path / "resumed" / PVD)
    assert (tmp_path / "resumed" / PVD).read_text() == (tmp_path / "full" / PVD).read_text()
    # timestep λ under force control; the increment index under arc length
    lam = full["load_factor"].values
    assert [t for t, _ in a] == (lam.tolist() if control == "force" else [0.0, 1.0, 2.0])
    for k, ((_, x), (_, y)) in enumerate(zip(a, b)):
        assert x.array_names == y.array_names
        for name in ("u", "u_magnitude", "energy_density", "bending_fraction"):
            scale = max(float(np.abs(x.point_data[name]).max()), 1.0)
            np.testing.assert_allclose(y.point_data[name], x.point_data[name], rtol=0,
                                       atol=1e-8 * scale, err_msg=name)
        np.testing.assert_array_equal(x.point_data["u"], full["displacement_field"].values[k])


def test_a_resume_with_other_settings_is_refused_naming_the_key(tmp_path, monkeypatch):
    _run_killed_after(monkeypatch, tmp_path / "killed", 1)
    with pytest.raises(ConfigError, match=r"study\.n_increments = 3.*study\.n_increments = 4"):
        _run(tmp_path / "other", "study.n_increments=4",
             f"study.resume_from={tmp_path / 'killed'}")


def test_resume_from_a_missing_or_unusable_directory_is_one_clear_error(tmp_path):
    study_dir = tmp_path / "run"
    with pytest.raises(InputError, match=r"resume_from=/nonexistent: no such directory"):
        _run(study_dir, "study.resume_from=/nonexistent")
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(InputError, match=r"has no increments\.nc"):
        _run(study_dir, f"study.resume_from={empty}")
    (empty / "increments.nc").write_bytes(b"")   # a 0-byte file, as an old kill could leave
    with pytest.raises(InputError, match=r"cannot be read .* damaged"):
        _run(study_dir, f"study.resume_from={empty}")


def test_resume_from_nonexistent_on_the_command_line_is_one_line(tmp_path, run_cli):
    r = run_cli("pointatlas", *SMALL, "study.resume_from=/nonexistent",
                f"outputs_root={tmp_path / 'out'}", "quiet=true", cwd=tmp_path)
    # refused at start-up (exit 2), before a run directory is made
    assert r.returncode == 2
    lines = [line for line in r.stderr.strip().splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr[-2000:]
    assert "study.resume_from=/nonexistent: no such directory" in lines[0]
    assert not list((tmp_path / "out").glob("runs/*/*"))


def test_an_interrupted_write_keeps_the_saved_increments_and_is_cleaned(tmp_path, monkeypatch):
    """A kill during the write of increment 2 leaves increments.nc with increment 1 intact and
    a temporary file; the next run in the directory (and a resume from it) removes it."""
    run_dir = tmp_path / "killed"
    real = store.write_increments

    def die_while_writing(path, ds, records, settings):
        if len(records) == 2:
            # the temporary file is half written when the kill comes
            (path.parent / f".{path.name}.0123456789ab.tmp").write_bytes(b"\x89HDF\r\n")
            raise Killed
        real(path, ds, records, settings)

    monkeypatch.setattr(store, "write_increments", die_while_writing)
    with pytest.raises(Killed):
        _run(run_dir)
    monkeypatch.setattr(store, "write_increments", real)
    (run_dir / "increments.partial.nc").write_bytes(b"")   # what older versions left
    with xr.open_dataset(run_dir / "increments.nc") as saved:
        assert saved.sizes["increment"] == 1
        assert float(saved["load_factor"][0]) == pytest.approx(0.05 / 3)
    # a resume reads the complete file and removes the leftovers
    ctx = composed_context(tmp_path / "next", SMALL)
    records = store.read_increments(run_dir, store.run_settings(ctx))
    assert [r.load_factor for r in records] == pytest.approx([0.05 / 3])
    assert records[0].state is not None and records[0].reactions is not None
    # what is left: the saved increment and its ParaView snapshot, listed in the .pvd
    kept = ["increments.nc", PVD, "snapshots"]
    assert sorted(p.name for p in run_dir.iterdir()) == kept
    assert [p.name for p in (run_dir / "snapshots").iterdir()] == ["increment_0000.vtp"]
    # and so does the start of a run in that directory (here one that stops at once)
    (run_dir / ".increments.nc.ba9876543210.tmp").write_bytes(b"")
    with pytest.raises(InputError):
        _run(run_dir, "study.resume_from=/nonexistent")
    assert sorted(p.name for p in run_dir.iterdir()) == kept
