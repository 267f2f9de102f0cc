"""ASAM OpenSCENARIO XML 1.0-1.3 reading: schema validation, parameters and expressions,
catalogs, distributions, and the translation of positions, actions and conditions into the
scenario model."""
