"""The JAMA surrounding-vehicle blind-spot catalogue (4.2.2.1): positions, reduction, the
generated scenarios, the ray-cast occlusion check and the closed-loop runs."""
