"""The fleet: drones flying between airports, their trajectories and their separation."""
