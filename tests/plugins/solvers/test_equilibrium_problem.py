"""The protocol lists what the path followers use; the test problems provide it."""
from pointatlas_solvers.equilibrium_problem import EquilibriumProblem

from .test_arc_length import CubicSpring
from .test_branch_switching import Pitchfork

#: used by every path follower (the module doc of equilibrium_problem)
ALWAYS = ("F", "C", "g", "rho", "residual", "scale", "system", "energy_parts",
          "n_components", "row_support")


def members():
    return set(EquilibriumProblem.__annotations__) | {
        k for k in vars(EquilibriumProblem) if not k.startswith("_")}


def test_the_protocol_holds_exactly_the_members_its_doc_assigns():
    assert members() == {*ALWAYS, "merit", "lbfgs", "length_scale", "arc_mask"}


def test_the_test_problems_provide_what_every_follower_uses():
    for eq in (CubicSpring(), Pitchfork()):
        missing = [m for m in (*ALWAYS, "length_scale", "arc_mask") if not hasattr(eq, m)]
        assert not missing, (type(eq).__name__, missing)
