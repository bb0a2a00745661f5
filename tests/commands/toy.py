"""A toy command for the declaration tests: an option added here must reach --help, manifests and
the function, with nothing else written."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import click

from fishgen.commands import Command, Events, Inputs, Made, Output
from fishgen.options import FiniteRange, option

SEEN: list = []


@dataclass(frozen=True)
class ToyOptions:
    brightness: float = option(FiniteRange(0, 10), "How bright the toy shines.", 2.5)
    colour: str = option(click.Choice(["red", "blue"]), "Its colour.", "red")


COMMAND = Command(name="toy", summary="A toy.", help="A toy command.", options=ToyOptions,
                  run="tests.commands.toy:toy", inputs=Inputs("INPUT..."), output=Output("Where."),
                  batch=True)


def toy(inputs: tuple[Path, ...], output, options: ToyOptions, events: Events) -> Made:
    SEEN.append(options)
    Path(output).write_text(f"{options.brightness} {options.colour}\n")
    return Made((Path(output),), tuple(inputs), (f"toy {options.brightness}",))
