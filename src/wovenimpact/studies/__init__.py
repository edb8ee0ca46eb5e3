"""Studies over many runs: sweeps, ballistic limits, design searches."""
