"""Outputs: JSON and GeoJSON files, PNG plots; every file is written whole or not at all."""
