"""Wiring of the stages: plan → scene → execution with verification → dataset."""
