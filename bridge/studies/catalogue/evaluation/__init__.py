"""Running the catalogue: C&C expectations (closed form or the C&C driver as a reference ego),
concrete runs and the resumable campaign."""
