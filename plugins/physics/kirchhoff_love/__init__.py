"""Kirchhoff–Love thin shells on point-set atlases (thesis §4, Papers 1–2)."""
