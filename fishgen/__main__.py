from fishgen.cli import main

main()
