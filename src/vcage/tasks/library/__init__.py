"""The built-in atomic tasks, one module each, named after the task it registers in ``TASKS``.

Every module of this package is imported when the package is, so a new task is one new file here.
"""

import importlib
import pkgutil

MODULES = tuple(sorted(m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")))
for _module in MODULES:
    importlib.import_module(f"{__name__}.{_module}")
