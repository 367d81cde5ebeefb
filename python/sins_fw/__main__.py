"""`python -m sins_fw` runs the CLI."""

from sins_fw.launch import entry

# Guarded: a worker process started with `spawn` (Dask's LocalCluster) imports the main module again.
if __name__ == "__main__":
    entry()
