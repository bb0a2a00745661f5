"""The fin techniques of thesis chapter 5 (a leaf module: the CLI lists them without numpy)."""

FIN_MODES = ("blend", "mask", "opaque")
