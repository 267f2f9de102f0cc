"""Many runs: sweeps (local process pool or Ray), the UN R157 judge, the SCT incident study."""
