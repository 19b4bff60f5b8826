"""The 97-type 25 Hz phase-sensitive track circuit: the model, the sweep against ballast, liansuo 25hz."""
