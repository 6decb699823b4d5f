"""The `fleetsim` command."""
