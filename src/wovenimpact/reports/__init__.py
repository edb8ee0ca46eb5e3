"""Generators of the validation pages (``wovenimpact validate``, docs/validation*.md): they
run or reuse the studies and verification problems and write their tables and figures."""
