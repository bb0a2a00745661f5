"""Assembly: species + geometry -> a scene of parts, materials, textures and animation."""
