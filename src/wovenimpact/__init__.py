"""wovenimpact: explicit dynamics of impacts on dry woven fabric and metal.

Public API for this stage: the yarn-crossover material model usable on its own.
"""

__version__ = "0.1.0"
