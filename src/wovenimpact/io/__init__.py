"""Files a run reads and writes: atomic writes, checkpoints, time histories, field output."""
