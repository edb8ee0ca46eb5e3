"""The acceptance corpus of bad inputs (issue 12): :mod:`tests.corpus.generate` writes
them, :mod:`tests.corpus.runner` runs each through the CLI and classifies the result."""
