import numpy as np
import pytest

from pointatlas.errors import ConfigError, InputError
from pointatlas_sources.point_file import PointFile


@pytest.fixture
def cloud():
    return np.random.default_rng(0).normal(size=(50, 3))


def test_npz_round_trip_with_markers(tmp_path, cloud):
    path = tmp_path / "pts.npz"
    np.savez(path, points=cloud, markers=cloud[:10])
    pc = PointFile(path=str(path), intrinsic_dim=2).load(np.random.default_rng(0))
    np.testing.assert_array_equal(pc.points, cloud)
    np.testing.assert_array_equal(pc.markers, cloud[:10])
    assert pc.intrinsic_dim == 2 and pc.name == "pts"


def test_npz_high_dimensional(tmp_path):
    X = np.random.default_rng(1).normal(size=(20, 7))
    np.savez(tmp_path / "x.npz", points=X)
    pc = PointFile(path=str(tmp_path / "x.npz")).load(None)
    assert pc.points.shape == (20, 7) and pc.markers is None


@pytest.mark.parametrize("suffix", [".vtp", ".vtk", ".ply"])
def test_pyvista_round_trip(tmp_path, cloud, suffix):
    pv = pytest.importorskip("pyvista")
    path = tmp_path / f"cloud{suffix}"
    pv.PolyData(cloud).save(str(path))
    pc = PointFile(path=str(path)).load(np.random.default_rng(0))
    # .ply stores float32 unless told otherwise
    np.testing.assert_allclose(pc.points, cloud, rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("suffix, delimiter, header", [
    (".csv", ",", "x,y,z"), (".txt", " ", ""), (".csv", ",", "")])
def test_text_round_trip(tmp_path, cloud, suffix, delimiter, header):
    path = tmp_path / f"c{suffix}"
    np.savetxt(path, cloud, delimiter=delimiter, header=header, comments="")
    np.testing.assert_allclose(PointFile(path=str(path)).load(None).points, cloud, rtol=1e-15)


def test_missing_path_is_a_config_error():
    with pytest.raises(ConfigError, match="path is missing"):
        PointFile().load(None)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        PointFile(path=str(tmp_path / "nope.npz")).load(None)


def test_unknown_extension(tmp_path):
    (tmp_path / "a.xls").write_text("1")
    with pytest.raises(InputError, match="unknown file extension '.xls'.*npz"):
        PointFile(path=str(tmp_path / "a.xls")).load(None)


def test_npz_without_points(tmp_path, cloud):
    np.savez(tmp_path / "a.npz", X=cloud)
    with pytest.raises(InputError, match=r"no array named 'points'.*\['X'\].*savez"):
        PointFile(path=str(tmp_path / "a.npz")).load(None)


def test_bad_shape(tmp_path):
    np.savez(tmp_path / "a.npz", points=np.zeros((2, 3, 4)))
    with pytest.raises(InputError, match=r"2-D array.*\(2, 3, 4\)"):
        PointFile(path=str(tmp_path / "a.npz")).load(None)


def test_nan_rows_are_named(tmp_path, cloud):
    cloud[[3, 17], 1] = np.nan
    np.savez(tmp_path / "a.npz", points=cloud)
    with pytest.raises(InputError, match=r"NaN or inf in 2 row\(s\) \(first: \[3, 17\]\)"):
        PointFile(path=str(tmp_path / "a.npz")).load(None)


def test_unparsable_text(tmp_path):
    (tmp_path / "a.csv").write_text("x,y\nhello,world\n1,2\n")
    with pytest.raises(InputError, match="cannot parse"):
        PointFile(path=str(tmp_path / "a.csv")).load(None)


def test_bad_intrinsic_dim(tmp_path, cloud):
    np.savez(tmp_path / "a.npz", points=cloud)
    with pytest.raises(ConfigError, match="intrinsic_dim=5"):
        PointFile(path=str(tmp_path / "a.npz"), intrinsic_dim=5).load(None)


def test_n_points_keeps_a_seeded_subset(tmp_path):
    import numpy as np
    from pointatlas_sources.point_file import PointFile

    X = np.random.default_rng(0).random((100, 3))
    np.savez(tmp_path / "p.npz", points=X)
    a = PointFile(path=str(tmp_path / "p.npz"), n_points=40).load(np.random.default_rng(1))
    b = PointFile(path=str(tmp_path / "p.npz"), n_points=40).load(np.random.default_rng(1))
    assert a.points.shape == (40, 3) and np.array_equal(a.points, b.points)
    assert PointFile(path=str(tmp_path / "p.npz"), n_points=500).load(np.random.default_rng(1)).n_points == 100


def test_farthest_subsample_is_quasi_uniform_and_random_is_available(tmp_path):
    import numpy as np
    from scipy.spatial import cKDTree
    from pointatlas.errors import ConfigError
    from pointatlas_sources.point_file import PointFile

    X = np.random.default_rng(0).random((3000, 2))
    np.savez(tmp_path / "p.npz", points=X)

    def min_spacing(P):
        return cKDTree(P).query(P, k=2)[0][:, 1].min()

    far = PointFile(path=str(tmp_path / "p.npz"), n_points=300).load(np.random.default_rng(1))
    rnd = PointFile(path=str(tmp_path / "p.npz"), n_points=300,
                    subsample="random").load(np.random.default_rng(1))
    assert far.n_points == rnd.n_points == 300
    # 300 points in the unit square: mean spacing ≈ 0.058; farthest-point keeps pairs apart
    assert min_spacing(far.points) > 0.03 and min_spacing(rnd.points) < 0.01
    with pytest.raises(ConfigError, match="subsample='grid'"):
        PointFile(path=str(tmp_path / "p.npz"), n_points=30, subsample="grid").load(None)


# -- bad input: one clear InputError naming the file, the problem and the fix (issue 15) -----

@pytest.mark.parametrize("array, dtype_text", [
    (np.array([["a", "b", "c"], ["d", "e", "f"]]), "<U1 (text)"),
    (np.ones((4, 3), dtype=bool), "bool (booleans)"),
    (np.ones((4, 3), dtype=complex), "complex128 (complex numbers)"),
])
def test_npz_of_non_numbers_names_key_dtype_and_fix(tmp_path, array, dtype_text):
    path = tmp_path / "s.npz"
    np.savez(path, points=array)
    with pytest.raises(InputError) as info:
        PointFile(path=str(path)).load(None)
    msg = str(info.value)
    assert f"{path}: array 'points' has dtype {dtype_text}" in msg
    assert "numpy.savez(path, points=X.astype(float))" in msg and "\n" not in msg


def test_npz_markers_of_strings_are_named(tmp_path, cloud):
    np.savez(tmp_path / "m.npz", points=cloud, markers=np.array([["x", "y", "z"]]))
    with pytest.raises(InputError, match=r"array 'markers' has dtype <U1 \(text\)"):
        PointFile(path=str(tmp_path / "m.npz")).load(None)


def test_integer_npz_is_read_as_float(tmp_path):
    X = np.arange(12).reshape(4, 3)
    np.savez(tmp_path / "i.npz", points=X)
    pc = PointFile(path=str(tmp_path / "i.npz")).load(None)
    assert pc.points.dtype == np.float64 and np.array_equal(pc.points, X)


PLY_HEADER = ("ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\n"
              "property float z\nend_header\n")


@pytest.mark.parametrize("name, content, expected", [
    ("garbage.ply", "hello world\nnot a ply\n",
     r"garbage.ply could not be parsed as PLY \(VTK: Could not open PLY file\)\. Check that the "
     r"file is a valid PLY dataset, or save the points with numpy.savez"),
    ("no_vertices.ply", PLY_HEADER.format(n=0), r"no_vertices.ply holds no points\. Give a file"),
    ("garbage.vtk", "garbage\n", r"garbage.vtk could not be parsed as VTK \(Unrecognized file "
                                 r"type: garbage"),
])
def test_unparsable_or_empty_mesh_is_one_line_and_vtk_is_silent(tmp_path, capfd, name, content,
                                                                expected):
    pytest.importorskip("pyvista")
    path = tmp_path / name
    path.write_text(content)
    with pytest.raises(InputError, match=expected) as info:
        PointFile(path=str(path)).load(None)
    assert "\n" not in str(info.value) and "0x" not in str(info.value)
    out, err = capfd.readouterr()  # VTK writes to the C-level stdout/stderr
    assert "vtk" not in (out + err).lower(), out + err


def test_a_valid_ply_still_reads_after_a_bad_one(tmp_path, capfd):
    """Silencing VTK is scoped to the read: verbosity and logging come back unchanged."""
    import logging

    pv = pytest.importorskip("pyvista")
    (tmp_path / "bad.ply").write_text("nonsense")
    (tmp_path / "ok.ply").write_text(PLY_HEADER.format(n=3) + "0 0 0\n1 0 0\n0 1 0\n")
    before = pv.vtk_verbosity(), list(logging.getLogger().filters)
    with pytest.raises(InputError):
        PointFile(path=str(tmp_path / "bad.ply")).load(None)
    pc = PointFile(path=str(tmp_path / "ok.ply")).load(None)
    np.testing.assert_array_equal(pc.points, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    assert (pv.vtk_verbosity(), list(logging.getLogger().filters)) == before


@pytest.mark.parametrize("suffix", [".ply", ".npz", ".csv"])
def test_zero_byte_file_is_named_empty(tmp_path, suffix):
    path = tmp_path / f"empty{suffix}"
    path.write_bytes(b"")
    with pytest.raises(InputError, match=r"empty\.\w+ is empty \(0 bytes\): it holds no points"):
        PointFile(path=str(path)).load(None)


def test_directory_is_named_as_such(tmp_path):
    (tmp_path / "scans.npz").mkdir()
    with pytest.raises(InputError, match=r"scans.npz is a directory, not a file of points\. "
                                         r"Give a file in it"):
        PointFile(path=str(tmp_path / "scans.npz")).load(None)


def test_header_only_text_file_holds_no_points(tmp_path):
    (tmp_path / "h.csv").write_text("x,y,z\n")
    with pytest.warns(UserWarning):  # numpy: "input contained no data"
        with pytest.raises(InputError, match=r"h.csv holds no points"):
            PointFile(path=str(tmp_path / "h.csv")).load(None)


@pytest.mark.skipif(not hasattr(__import__("os"), "geteuid") or __import__("os").geteuid() == 0,
                    reason="root reads files whatever their mode")
def test_unreadable_file_is_named(tmp_path, cloud):
    path = tmp_path / "locked.npz"
    np.savez(path, points=cloud)
    path.chmod(0)
    try:
        with pytest.raises(InputError, match=r"locked.npz cannot be read \(Permission denied\)"):
            PointFile(path=str(path)).load(None)
    finally:
        path.chmod(0o600)


def test_read_failure_of_the_file_is_named(tmp_path, cloud, monkeypatch):
    """The same refusal where the permission check cannot bite (tests run as root): any OS
    error on opening the file is one line with the fix."""
    import pointatlas_sources.point_file as point_file

    path = tmp_path / "locked.npz"
    np.savez(path, points=cloud)

    def denied(file, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(file))

    monkeypatch.setattr(point_file, "open", denied, raising=False)
    with pytest.raises(InputError, match=r"locked.npz cannot be read \(Permission denied\)\. "
                                         r"Make it readable \(chmod u\+r"):
        PointFile(path=str(path)).load(None)


@pytest.mark.parametrize("name, content, expected, code", [
    ("garbage.ply", "hello world\n", "could not be parsed as PLY", 1),
    ("strings.npz", None, "array 'points' has dtype <U1 (text)", 1),
    ("a.xls", "1", "unknown file extension '.xls'", 2),    # refused at start-up
    ("empty.ply", "", "is empty (0 bytes)", 2),
])
def test_cli_bad_file_is_one_line_without_vtk_output(tmp_path, run_cli, name, content, expected,
                                                      code):
    """End to end: exit 1 (2 when refused at start-up, with no run directory), the error as
    the last line, no traceback, no VTK or pyvista lines."""
    path = tmp_path / name
    if content is None:
        np.savez(path, points=np.array([["a", "b", "c"]]))
    else:
        path.write_text(content)
    proc = run_cli("pointatlas", "~experiment", "study=embedding", "embedder=pca", "source=file",
                   f"source.path={path}", f"outputs_root={tmp_path}/out",
                   f"hydra.run.dir={tmp_path}/run", cwd=tmp_path)
    assert proc.returncode == code, proc.stderr
    assert (tmp_path / "run").exists() == (code == 1)
    lines = [line for line in (proc.stdout + proc.stderr).splitlines() if line.strip()]
    assert lines[-1].startswith("pointatlas: error: ") and expected in lines[-1], lines
    assert "Traceback" not in proc.stderr
    # before the error: the run's start-up log line only, nothing from VTK or pyvista
    assert not [line for line in lines[:-1] if "vtk" in line.lower() or "warn" in line.lower()
                or "error" in line.lower()], lines
