"""Actions that steer an actor towards a goal re-computed every step: synchronisation with a
master, speed profiles, lateral distances."""
