# Blender loads an extension from the folder holding blender_manifest.toml and this file.
from .addon import register, unregister  # noqa: F401
