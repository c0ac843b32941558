import numpy as np
from scipy.spatial import cKDTree


def nn_distances(X: np.ndarray) -> np.ndarray:
    """Distance from each point to its nearest other point."""
    return cKDTree(X).query(X, k=2)[0][:, 1]
