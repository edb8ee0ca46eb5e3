"""Input layer: files with units → validated SI parameter sets (docs/model.md, units)."""

from wovenimpact.spec.fields import InputWarning
from wovenimpact.spec.material import load_material, material_from_dict

__all__ = ["InputWarning", "load_material", "material_from_dict"]
