"""Monte Carlo: random streams, integrators, the compiled ensemble kernel, simulations and sweeps."""
