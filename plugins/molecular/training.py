"""Train a SandCV from frames: superpose the CV atoms (mdtraj), embed (any embedder plugin),
parametrise with LME (:class:`.sandcv.SandCV`)."""
from __future__ import annotations

import numpy as np

from pointatlas.errors import InputError

from .ensemble import aligned, check_training
from .sandcv import SandCV


def train_sandcv(frames, atoms, embedder, approximant, n_bins: int, tol: float = 1e-12,
                 min_conditioning: float = 0.1):
    """(cv, Z, Q) from ``frames`` (N, n_atoms, 3) nm restricted to ``atoms``; Z the aligned
    CV-atom frames (N, len(atoms), 3), Q their embedding (N, d)."""
    Z, ref = aligned(frames, atoms)
    d = int(getattr(embedder, "n_components", 1))
    check_training(len(Z), d, int(getattr(embedder, "n_neighbors", 0) or 0))
    try:
        Q = embedder.fit_transform(Z.reshape(len(Z), -1))
    except InputError as err:
        raise InputError(f"embedding the training frames failed: {err}") from None
    cv = SandCV(approximant, n_bins, tol=tol, min_conditioning=min_conditioning)
    cv.fit(Z, Q, ref)
    return cv, Z, np.asarray(Q)
