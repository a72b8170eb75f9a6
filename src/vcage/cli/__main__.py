"""``python -m vcage.cli``."""

from vcage.cli import main

main()
