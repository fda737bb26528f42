"""Benchmarks: skyroute's planners against peer libraries on the same queries."""
