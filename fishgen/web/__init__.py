"""fishgen's local web pages: the server they share."""
