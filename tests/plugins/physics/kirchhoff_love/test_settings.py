"""Shell settings: every invalid support, load or number is named with its fix."""
import pytest

from pointatlas.errors import ConfigError
from pointatlas_kit.selectors import Selector
from pointatlas_physics.kirchhoff_love.settings import Load, ShellSettings, Support, check_settings


def _ok(**kw):
    base = dict(supports=[Support(kind="clamped", where=Selector(plane=[1, 0, 0, 0]))],
                loads=[Load(kind="point", at=[0, 0, 0], force=[0, 0, -1])])
    base.update(kw)
    return ShellSettings(**base)


def test_valid_settings_pass():
    check_settings(_ok())
    for solver in ("direct", "cg_ilu", "superlu", "pardiso", "cg_amg", "auto"):
        check_settings(_ok(solver=solver))


@pytest.mark.parametrize("kw, match", [
    (dict(thickness=0.0), r"^physics\.thickness=0\.0 is invalid: it must be a number > 0\."),
    (dict(young_modulus=-1.0), r"^physics\.young_modulus=-1\.0 is invalid"),
    (dict(poisson_ratio=0.5), r"^physics\.poisson_ratio=0\.5 is invalid: it must be a number in "
                              r"\(-1, 0\.5\)\. Pass e\.g\. physics\.poisson_ratio=0\.3\.$"),
    (dict(poisson_ratio=float("nan")), r"^physics\.poisson_ratio=nan is invalid"),
    (dict(penalty=float("inf")), r"^physics\.penalty=inf is invalid"),
    (dict(ghost_layers=-1), r"^physics\.ghost_layers=-1 is invalid: it must be an integer >= 0"),
    (dict(segment_points=True), r"^physics\.segment_points=True is invalid"),
    (dict(supports=[]), "supports is empty"),
    (dict(supports=[Support(kind="glued")]), r"^physics\.supports\[0\]\.kind='glued' is invalid: "
                                             r"it must be one of 'clamped', "),
    (dict(supports=[Support(kind="symmetry")]), "needs normal"),
    (dict(supports=[Support(kind="symmetry", normal=[1, 0])]),
     r"^physics\.supports\[0\]\.normal=\[1, 0\] is invalid: it must be a list of 3 items"),
    (dict(supports=[Support(kind="fixed")]), "needs components"),
    (dict(supports=[Support(kind="fixed", components=[3])]),
     r"^physics\.supports\[0\]\.components=\[3\] is invalid: .*one of 0, 1, 2"),
    (dict(loads=[Load(kind="point", force=[0, 0, 1])]), "needs at"),
    (dict(loads=[Load(kind="point", at=[0, 0, 0], force=[0, float("nan"), 1])]),
     r"^physics\.loads\[0\]\.force=\[0, nan, 1\] is invalid"),
    (dict(loads=[Load(kind="pressure")]), "needs pressure"),
    (dict(loads=[Load(kind="line", force=[0, 0, 1])]), "needs where"),
    (dict(streamed_assembly=True, loads=[Load(kind="pressure", pressure=1.0)]),
     r"^physics\.loads\[0\] \(pressure\) needs the basis at the Gauss points, which "
     r"physics\.streamed_assembly=true does not keep: remove streamed_assembly or use point "
     r"and line loads\.$"),
    (dict(streamed_assembly="yes"), r"^physics\.streamed_assembly='yes' is invalid"),
    (dict(solver="magic"), r"^physics\.solver='magic' is invalid: it must be one of 'direct', "
                           r"'cg_ilu', 'superlu', 'pardiso', 'cg_amg', 'auto'\. Pass e\.g\. "
                           r"physics\.solver=auto\.$"),
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
