"""The run plan: what a checked config makes the run do (its jobs, their inputs,
parameters and outputs, and the targets)."""
