"""Analytic and semi-analytic methods: equivalent linearisation, stochastic averaging, Fokker-Planck solvers, exact reference results."""
