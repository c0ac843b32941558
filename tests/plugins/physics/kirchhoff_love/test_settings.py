"""Shell settings: every invalid support, load or number is named with its fix."""
import pytest

from pointatlas.errors import ConfigError
from pointatlas_physics.kirchhoff_love.selectors import Selector
from pointatlas_physics.kirchhoff_love.settings import Load, ShellSettings, Support, check_settings


def _ok(**kw):
    base = dict(supports=[Support(kind="clamped", where=Selector(plane=[1, 0, 0, 0]))],
                loads=[Load(kind="point", at=[0, 0, 0], force=[0, 0, -1])])
    base.update(kw)
    return ShellSettings(**base)


def test_valid_settings_pass():
    check_settings(_ok())


@pytest.mark.parametrize("kw, match", [
    (dict(thickness=0.0), "thickness"),
    (dict(young_modulus=-1.0), "young_modulus"),
    (dict(poisson_ratio=0.5), "poisson_ratio"),
    (dict(supports=[]), "supports is empty"),
    (dict(supports=[Support(kind="glued")]), "kind = 'glued'"),
    (dict(supports=[Support(kind="symmetry")]), "needs normal"),
    (dict(supports=[Support(kind="fixed")]), "needs components"),
    (dict(supports=[Support(kind="fixed", components=[3])]), "components"),
    (dict(loads=[Load(kind="point", force=[0, 0, 1])]), "needs at"),
    (dict(loads=[Load(kind="pressure")]), "needs pressure"),
    (dict(loads=[Load(kind="line", force=[0, 0, 1])]), "needs where"),
    (dict(solver="magic"), "solver"),
])
def test_invalid_settings_are_named(kw, match):
    with pytest.raises(ConfigError, match=match):
        check_settings(_ok(**kw))


def test_consistent_chart_hessians_are_refused_for_shells():
    from pointatlas_atlas.settings import AtlasSettings
    from pointatlas_physics.kirchhoff_love.plugin import KirchhoffLove

    KirchhoffLove.factories(None, AtlasSettings())
    with pytest.raises(ConfigError, match="chart_hessians = 'consistent' is not available for "
                                          "shells.*surface_geometry"):
        KirchhoffLove.factories(None, AtlasSettings(chart_hessians="consistent"))


def test_polynomial_fit_charts_are_refused_for_shells():
    from pointatlas_atlas.settings import AtlasSettings
    from pointatlas_physics.kirchhoff_love.plugin import KirchhoffLove

    with pytest.raises(ConfigError, match="chart_reproduction = 'quartic' is not available for "
                                          "shells.*surface_geometry"):
        KirchhoffLove.factories(None, AtlasSettings(chart_reproduction="quartic"))
