"""chainsim_plot: draws the outputs of a chainsim run (`chainsim plot RUN_DIR`, or
`/usr/bin/python3 -m chainsim_plot RUN_DIR` with PYTHONPATH=<source>/python). See docs/plotting.md."""
