// output (in progress)
