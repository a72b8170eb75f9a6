"""Annotated object catalog: procedurally built object types with semantic and grasp metadata.

Importing this package fills ``CATALOG``: it imports :mod:`vcage.assets.objects`, whose modules
register the built-in types. Python runs this ``__init__`` before any submodule, so
``from vcage.assets.catalog import CATALOG`` always yields the full catalog.
"""

from vcage.assets import objects  # noqa: F401  (registers the built-in types)
from vcage.assets.catalog import CATALOG, Catalog, ObjectType

__all__ = ["CATALOG", "Catalog", "ObjectType"]
