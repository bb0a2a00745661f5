from fishgen.cli import run

run()
