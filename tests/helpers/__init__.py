"""Helpers shared by the test files (importable as ``helpers``: tests/ is on the path)."""
