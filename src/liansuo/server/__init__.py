"""The classroom server: simulations held for trainee seats and an instructor, served over a websocket
(docs/classroom.md)."""
