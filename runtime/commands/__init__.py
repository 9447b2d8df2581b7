"""One module per ``volerr`` command; each has ``register(subparsers)``."""
