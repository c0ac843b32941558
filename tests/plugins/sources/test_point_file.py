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
