"""Fuzzing (docs/robustness.md): the runner, liansuo fuzz, and every kind: station files, command lines, recordings,
console sessions."""
