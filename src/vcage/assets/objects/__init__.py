"""Built-in object types; importing this package registers them in ``CATALOG``."""

from vcage.assets.objects import (  # noqa: F401
    blocks,
    containers,
    devices,
    household,
    kitchen,
    office,
    playthings,
    sundries,
    tools,
)
