"""`fishgen view`: a single-file three.js viewer page for an asset, served on loopback."""
