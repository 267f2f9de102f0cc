"""The stages of ``hiyari demo`` (``make demo``)."""
