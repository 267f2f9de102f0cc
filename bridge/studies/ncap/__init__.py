"""Euro NCAP 2023 AEB Car-to-Car and VRU tests: the protocols' grids run on Vector's
OpenSCENARIO files, scored by the assessment rules (``hiyari ncap``)."""
