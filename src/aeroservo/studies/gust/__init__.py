"""Gust and turbulence loads of CS-25.341: the study over flight points (:mod:`.study`), its
runs, results and figures."""
