from roverlab.cli.main import main

main()
