"""VRFish species parameter files: typed model and parser."""
from fishgen.species.model import Species
from fishgen.species.parser import load_species, parse_species

__all__ = ["Species", "load_species", "parse_species"]
