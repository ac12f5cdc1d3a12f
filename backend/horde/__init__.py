"""Horde Lab: many predictions learned at once with the Horde architecture."""
