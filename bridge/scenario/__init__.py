"""Scenarios: the scenario model, its readers and the closed loop that runs it on SUMO."""
