"""Jobs on folders of files and the command line: the only layer that prints or shows
progress."""
