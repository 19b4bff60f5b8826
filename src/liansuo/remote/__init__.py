"""The classroom's clients: the console on a seat of the classroom server, the instructor's dashboard and the
login (docs/classroom.md)."""
