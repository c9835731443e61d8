"""Materials: Johnson-Cook plasticity and damage, material library (TC4, user TOML files)."""

from robobore.material.library import Material, bundled_materials, load_material

__all__ = ["Material", "bundled_materials", "load_material"]
