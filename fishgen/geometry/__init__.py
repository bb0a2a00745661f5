"""Pure geometry: body and fin construction over numpy arrays (thesis units)."""
