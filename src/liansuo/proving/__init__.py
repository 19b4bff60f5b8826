"""What checks the world: the independent safety oracle, verify, soak, mutation testing, route-test scripts and
scenarios, and their pytest plugin and JUnit report.

Nothing here is used by the simulation itself; it stands apart from what it checks (docs/architecture.md, principle 7).
"""
