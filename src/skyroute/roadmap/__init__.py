"""Roadmaps over continuous worlds: built once, queried many times."""
