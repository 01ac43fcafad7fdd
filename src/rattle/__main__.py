"""``python -m rattle …`` is the same as ``rattle …``."""

from rattle.cli.main import main

if __name__ == "__main__":
    main()
