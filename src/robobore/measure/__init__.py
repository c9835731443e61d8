"""Measured cutting records in: readers, the paper's quantities, chatter detection."""
