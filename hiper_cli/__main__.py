from hiper_cli.cli import main

main()
