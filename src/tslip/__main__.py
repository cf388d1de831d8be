"""``python -m tslip``: the command line."""

from tslip.cli.main import main

main()
