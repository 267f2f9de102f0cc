"""Commands that judge: C&C boundaries, R157 points, the JAMA catalogue, perception coverage
and blind spots, the SCT incident study."""
