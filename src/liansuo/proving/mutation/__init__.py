"""Mutation testing: the seeded defects and liansuo mutate, which runs every check against each."""
