"""The engine's compiled passes (numba) and the plain maths they share with Python: measures,
the snapshot gather, trigger evaluation, motion, commands and the quiet step."""
