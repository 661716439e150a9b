"""Shared pytest setup. Long physics runs are marked ``slow`` and excluded by default."""
