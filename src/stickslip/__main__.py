"""``python -m stickslip``: the same command line as the ``stickslip`` script."""

from stickslip.cli.main import main

if __name__ == "__main__":
    main()
