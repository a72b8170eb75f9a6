"""Built-in object types; importing this package registers them in ``CATALOG``."""

from vcage.assets.objects import blocks, containers, devices, household, kitchen, office, tools  # noqa: F401
