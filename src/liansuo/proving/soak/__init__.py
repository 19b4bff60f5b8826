"""Random operation of a station against the safety oracle: liansuo soak."""
