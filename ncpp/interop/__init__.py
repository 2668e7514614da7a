"""Adapters between ncpp and other G-code libraries."""
