"""``python -m dvqp``: the command line (see :mod:`dvqp.cli`)."""

from dvqp.cli.main import command

if __name__ == "__main__":
    command()
