"""The ego stack: perception, fusion and planner (ACC + AEB) interfaces and built-in parts."""
