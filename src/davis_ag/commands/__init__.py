"""One module per ``davis-ag`` sub-command; each defines ``register(subparsers)``."""
