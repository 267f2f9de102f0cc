"""SUMO networks: generators (plain XML + netconvert), OpenDRIVE import, input checks."""
