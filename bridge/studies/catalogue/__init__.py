"""The JAMA traffic-disturbance catalogue (JAMA §4.1): combinations, their expansion over
surrounding-vehicle positions and lane counts by a geometric obstruction test, concrete
scenarios in the scenario model, C&C expectations, runs and the safety-argument report."""
