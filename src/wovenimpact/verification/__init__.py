"""Verification problems: small models built and stepped in code, whose answers the tests
check against closed forms and published solutions (Jones's impulsively loaded plate, a
rigid face striking a strip); the metal validation page reports the first."""
