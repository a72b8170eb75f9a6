"""Annotated object catalog: procedurally built object types with semantic and grasp metadata."""

from vcage.assets.catalog import CATALOG, Catalog, ObjectType

__all__ = ["CATALOG", "Catalog", "ObjectType"]
