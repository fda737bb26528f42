"""Vehicle models: turn a planned path (or a start and a goal) into what a vehicle flies."""
