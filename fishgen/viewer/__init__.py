"""`fishgen view`: a single-file three.js viewer page for an asset, served on loopback."""

from fishgen.exchange.client_limits import MAX_EMBED_BYTES

__all__ = ["MAX_EMBED_BYTES"]
