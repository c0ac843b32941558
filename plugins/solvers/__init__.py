"""Solvers shared by every physics on an atlas; they know no physics.

Linear-solver backends behind one interface (:mod:`.linear_backends`), the augmented
Lagrangian for linear constraints (:mod:`.augmented_lagrangian`), and path following of an
equilibrium problem given by the caller (:mod:`.equilibrium_problem`): Newton increments
with line search (:mod:`.increment`), load control (:mod:`.load_control`), arc length
(:mod:`.arc_length`), dispatched by :func:`.path_following.follow_path`; the stability check
(:mod:`.stability`), branch switching (:mod:`.branch_switching`), the stable-path descent
(:mod:`.stable_equilibrium`) and the resumable state of a path (:mod:`.path_state`).
"""
