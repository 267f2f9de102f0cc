"""The Safety Cushion Time driver model and the controller that applies it to SUMO vehicles."""
