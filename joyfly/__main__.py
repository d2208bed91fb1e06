"""`python -m joyfly`: the same as the `joyfly` command."""

from joyfly.cli import main

main()
