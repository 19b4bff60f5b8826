"""The kit every command stands on, the bottom floor: reading files within bounds with FILE:LINE:COLUMN errors,
what kind of file a file is, exit codes, JSON report heads, output, argument checks, text that fits, plot files."""
