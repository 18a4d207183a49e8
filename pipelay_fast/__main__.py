"""``python -m pipelay_fast``: the pipelay-fast command."""

from .cli import main

if __name__ == "__main__":
    raise SystemExit(main())
