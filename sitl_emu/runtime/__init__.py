"""Running vehicles: the node (a vehicle and its MAVLink links), the real-time runner and the swarm."""
