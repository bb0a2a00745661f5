"""`fishgen view`: a single-file three.js viewer page for an asset, served on loopback."""

MAX_EMBED_BYTES = 256 << 20
"""Beyond this a browser struggles with a base64 page; such assets need a desktop tool."""
