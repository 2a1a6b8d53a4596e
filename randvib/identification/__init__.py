"""Identification from records: record simulation, the Eq. 11 cost, SaDE search, plots."""
