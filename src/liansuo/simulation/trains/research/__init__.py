"""Research code: models of the source papers that the simulation does not drive. Each reproduces a paper's rules or
figures and is tested; no command uses it (docs/trains-automation.md)."""
