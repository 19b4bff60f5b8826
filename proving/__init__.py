"""What checks the world: the independent safety oracle (and, as the project grows, verify, soak and scripts).

Nothing here is used by the simulation itself; it stands apart from what it checks (DESIGN.md principle 7).
"""
