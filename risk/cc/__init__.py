"""The competent and careful (C&C) driver model, Preventable boundaries and UN R157 test points."""
