"""JAMA perception-disturbance principle coverage: factor x principle matrices per sensor
(Tables 4-23 to 4-27), the simulable disturbances they map to, and the coverage they give."""
