"""Perception and vehicle-motion disturbance runs by the JAMA method: principle coverage,
representative-factor sweeps, the blind-spot catalogue and grip-use reports."""
