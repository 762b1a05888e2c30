"""Observer-based boundary control: the assembled loop, its spectrum, simulation and tuning."""
