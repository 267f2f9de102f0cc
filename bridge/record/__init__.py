"""MCAP recording (ASAM OSI + Foxglove schemas), its reader and crash recovery."""
