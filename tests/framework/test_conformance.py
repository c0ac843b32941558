"""The plugin conformance suite (pointatlas.testing) on every installed plugin."""
import numpy as np
import pytest

from pointatlas.registry import FAMILIES, load_all
from pointatlas.testing import check_contract, check_plugin

SMALL = {
    ("source", "file"): None,  # needs a file: built in the test below
    ("source", "frames"): None,  # needs images: built in the test below
    ("source", "synthetic_metaboly"): {"n_frames": 4, "image_size": 256, "pixel_size": 0.4},
    ("source", "connected_pipes"): {"n_points": 400},
    ("source", "open_pipes"): {"n_points": 600},
    ("embedder", "nlie"): {"n_stress_neighbors": 15, "max_iter": 10, "lbfgs_max_iter": 50},
    ("physics", "kirchhoff_love_fracture"): {"length_scale": 0.15},   # required, no default
}
LINEAR = {("approximant", "lme"), ("approximant", "mls")}
# transform of a training point gives back its embedding exactly (to rounding: at most 1.0e-14
# of the spread measured) for pca, isomap and nlie, under check_embedder's default 1e-8. LLE and
# MLLE reconstruct a training point from its k nearest *other* training points, by design
# (pointatlas_embedders.out_of_sample.lle_extension): measured on check_embedder's
# swiss roll (seeds 0-2, with and without AIC), at most 1.8e-3 (LLE) and 9.5e-3 (MLLE) of the
# spread; allowed about 3x that.
TRANSFORM_RTOL = {("embedder", "lle"): 5e-3, ("embedder", "mlle"): 3e-2}


def installed():
    return [(family, name, cls) for group, family in FAMILIES.items()
            for name, cls in sorted(load_all(group).items())]


@pytest.mark.parametrize("family,name,cls", installed(), ids=lambda v: v if isinstance(v, str) else "")
def test_plugin_conforms(family, name, cls, tmp_path):
    kwargs = SMALL.get((family, name), {})
    if (family, name) == ("source", "file"):
        np.savez(tmp_path / "p.npz", points=np.random.default_rng(0).random((50, 3)))
        kwargs = {"path": str(tmp_path / "p.npz")}
    if (family, name) == ("source", "frames"):
        import imageio.v2 as imageio

        for k in range(3):
            imageio.imwrite(tmp_path / f"f{k}.png", np.full((16, 16), 40 * k, np.uint8))
        kwargs = {"path": str(tmp_path), "frame_rate": 2.0, "pixel_size": 0.5}
    if family == "source" and not kwargs and name not in ("file", "frames"):
        kwargs = {"n_points": 300}
    if family == "approximant":
        kwargs = {"reproduces_linear": (family, name) in LINEAR}
    if (family, name) in TRANSFORM_RTOL:
        kwargs = {**kwargs, "transform_rtol": TRANSFORM_RTOL[(family, name)]}
    check_plugin(family, cls, **kwargs)


def test_the_suite_catches_a_broken_embedder():
    class NoStore:
        description = "broken"

        from dataclasses import dataclass

        @dataclass
        class Config:
            n_components: int = 2

        def __init__(self, *, n_components=2):
            self.n_components = n_components + 1  # does not store unchanged

    with pytest.raises(AssertionError, match="must store 'n_components' unchanged"):
        check_contract(NoStore)


# -- transform (out-of-sample embedding) of an embedder --

def _pca():
    from pointatlas.registry import load_plugin

    return load_plugin("embedder", "pca")


class _Shifted(_pca()):
    """transform is off by 5% of the embedding's spread along its first axis."""

    def transform(self, X):
        Y = super().transform(X)
        spread = np.sqrt(np.mean(np.sum((self.embedding_ - self.embedding_.mean(0)) ** 2, 1)))
        return Y + [0.05 * spread, 0.0]


class _LookUp(_pca()):
    """transform gives back training points' embedding and 0 for any other point."""

    def fit(self, X, y=None):
        super().fit(X)
        self._train = np.asarray(X, dtype=float)
        return self

    def transform(self, X):
        X = self._validate_points(X, reset=False)
        hit = (X[:, None, :] == self._train[None]).all(axis=2)
        return np.where(hit.any(axis=1)[:, None], self.embedding_[hit.argmax(axis=1)], 0.0)


class _AcceptsNan(_pca()):
    def transform(self, X):
        return np.nan_to_num((np.asarray(X, dtype=float) - self.mean_) @ self.components_.T)


class _WrongShape(_pca()):
    def transform(self, X):
        return super().transform(X)[:, :1]


@pytest.mark.parametrize("cls,message", [
    (_Shifted, r"^_Shifted\.transform of training points is 0\.05 x the embedding's spread away"),
    (_LookUp, r"^_LookUp\.transform puts points 5% of a neighbour spacing from training points"),
    (_AcceptsNan, r"^_AcceptsNan\.transform accepted NaN coordinates; it must raise ValueError$"),
    (_WrongShape, r"^_WrongShape\.transform of 20 points has shape \(20, 1\), not \(20, 2\)$"),
])
def test_the_suite_catches_a_broken_transform(cls, message):
    with pytest.raises(AssertionError, match=message) as exc:
        check_plugin("embedder", cls)
    assert "\n" not in str(exc.value)


def test_transform_rtol_admits_an_approximate_extension():
    check_plugin("embedder", _Shifted, transform_rtol=0.06)  # 0.05 of the spread: allowed 0.06


def test_an_embedder_without_transform_passes():
    from dataclasses import dataclass

    class Projection:
        """The first two coordinates: fit / embedding_ only, no transform."""

        description = "first two coordinates"

        @dataclass
        class Config:
            n_components: int = 2

        def __init__(self, *, n_components=2):
            self.n_components = n_components

        def fit(self, X):
            X = np.asarray(X, dtype=float)
            if not np.isfinite(X).all():
                raise ValueError("X has NaN or inf")
            self.embedding_ = X[:, :self.n_components]
            return self

        def fit_transform(self, X):
            return self.fit(X).embedding_

    assert not hasattr(Projection, "transform")
    check_plugin("embedder", Projection)


def test_the_third_party_example_embedder_passes():
    spectral = pytest.importorskip("pointatlas_spectral.spectral",
                                   reason="examples/third_party_plugin not installed")
    assert not hasattr(spectral.SpectralEmbedder, "transform")
    check_plugin("embedder", spectral.SpectralEmbedder)


# -- the Dataset a physics' solve returns (pointatlas.physics_dataset_check) --

def _laplace_beltrami():
    from pointatlas.registry import load_plugin

    return load_plugin("physics", "laplace_beltrami")


@pytest.fixture(scope="module")
def solved_case():
    """(cloud, Dataset) of LaplaceBeltrami's conformance case: f = 1, u = 0 on the boundary."""
    from pointatlas.physics_dataset_check import solve_conformance_case

    cls = _laplace_beltrami()
    _, cloud, ds = solve_conformance_case(cls, cls.conformance_case)
    return cloud, ds


def test_the_conformance_case_solves_to_a_dataset_that_passes(solved_case):
    from pointatlas.physics_dataset_check import check_physics_dataset

    cloud, ds = solved_case
    assert cloud.n_points == 225 and ds.sizes["point"] == 225
    u = ds["u"].values
    # −Δu + u = 1 with u = 0 on the boundary: u vanishes on the whole boundary (the
    # supports hold every boundary point, not a shifted set), and its maximum lies a little
    # above the flat unit square's (Fourier series: 0.06981), the patch being curved
    xy = cloud.points[:, :2]
    edge = np.isclose(xy, 0.0, atol=1e-12).any(axis=1) | np.isclose(xy, 1.0, atol=1e-12).any(
        axis=1)
    assert edge.sum() == 56
    assert np.abs(u[edge]).max() < 1e-8
    assert 0.0698 < u.max() < 0.08
    check_physics_dataset(ds, _laplace_beltrami().fields, "LaplaceBeltrami", cloud.n_points)


def _drop_units(ds):
    del ds["u"].attrs["units"]
    return ds


def _unnamed_dim(ds):
    import xarray as xr

    # no dims given: xarray names it dim_0
    ds["residual_history"] = xr.DataArray(np.zeros(3), attrs={"long_name": "r", "units": "1"})
    return ds


@pytest.mark.parametrize("mutate,message", [
    (_drop_units, r"without 'long_name'/'units' attrs: \['u'\]"),
    (_unnamed_dim, r"variable 'residual_history' has unnamed dimension\(s\) \['dim_0'\]"),
])
def test_check_physics_fails_on_a_physics_whose_solve_breaks_the_schema(mutate, message):
    base = _laplace_beltrami()

    class BrokenPhysics(base):
        def solve(self, ctx, *, cloud, atlas_settings):
            return mutate(super().solve(ctx, cloud=cloud, atlas_settings=atlas_settings))

    with pytest.raises(AssertionError, match=r"BrokenPhysics\.solve's Dataset: .*" + message):
        check_plugin("physics", BrokenPhysics)


def _set(name, value):
    def mutate(ds):
        ds[name] = value
        return ds
    return mutate


def _empty_long_name(ds):
    ds["u"].attrs["long_name"] = " "
    return ds


def _non_finite(ds):
    ds["u"].values[7] = np.nan
    return ds


@pytest.mark.parametrize("mutate,message", [
    (_empty_long_name, r"variable 'u' has long_name=' ': it must be a non-empty string"),
    (_non_finite, r"variable 'u' has 1 non-finite value\(s\)"),
    (lambda ds: ds.drop_vars("u"), r"declared field 'u' is missing: no data variable 'u'"),
    (lambda ds: ds.drop_vars("point"), r"'point' is not a coordinate"),
    (_set("u", ((), 1.0, {"long_name": "u", "units": "1"})),
     r"declared field 'u' is missing: variable 'u' has dims \(\), without 'point'"),
    (_set("u", (("point", "c"), np.zeros((225, 2)), {"long_name": "u", "units": "1"})),
     r"field variable 'u' holds 2 value\(s\) per point; the declared field 'u' has 1"),
])
def test_the_dataset_check_names_the_variable_and_the_rule(solved_case, mutate, message):
    from pointatlas.physics_dataset_check import check_physics_dataset

    _, ds = solved_case
    bad = mutate(ds.copy(deep=True))
    with pytest.raises(AssertionError, match=r"^LaplaceBeltrami\.solve's Dataset: " + message):
        check_physics_dataset(bad, _laplace_beltrami().fields, "LaplaceBeltrami", 225)


def test_a_conformance_case_with_a_key_of_no_config_field_fails():
    with pytest.raises(AssertionError, match=r"conformance_case has key\(s\) \['sources'\]"):
        check_plugin("physics", _laplace_beltrami(), solve_case={"sources": "1"})
