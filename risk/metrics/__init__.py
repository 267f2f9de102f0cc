"""Risk metrics over plain arrays: time to contact, Safety Cushion Time, PET, incidents."""
