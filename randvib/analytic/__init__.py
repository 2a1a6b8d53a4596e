"""Analytic and semi-analytic methods: a declared family (method.py), each beside its mathematics (statistical linearisation, stochastic averaging, Fokker-Planck solvers), the driver that asks them (prediction.py), exact reference results."""

# The driver registers every method in randvib.analytic.method.METHODS, which the
# methods' refusals and randvib.transient_response read: loading it with the
# package makes the registry complete whichever analytic module is imported first.
from randvib.analytic import prediction  # noqa: E402, F401
