"""Phase-field brittle fracture of thin shells on the physics kit (issue 18)."""
