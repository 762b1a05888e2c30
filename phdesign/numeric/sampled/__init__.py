"""The observer for a controller: samplers, exact period maps, order, verification."""
