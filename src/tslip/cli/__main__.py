"""``python -m tslip.cli``: run the command-line interface."""

from .main import main

if __name__ == "__main__":
    main()
