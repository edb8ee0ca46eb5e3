"""What is read off a run: functions of a Model and a State (and of the history), which
step nothing — the impact outcome and per-ply energies, the fragment's outcome and the
casing's energies, metal thickness and plastic work, the mesh verdict."""
