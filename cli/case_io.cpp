// case_io (in progress)
