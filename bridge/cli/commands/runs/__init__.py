"""Commands that run scenarios and read their recordings: run, sweep, replay."""
