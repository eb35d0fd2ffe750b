// commands (in progress)
