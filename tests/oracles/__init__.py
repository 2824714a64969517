"""Independent oracles: a second implementation of the package's math, in NumPy, for tests."""
