"""The command line, the top floor: ``liansuo COMMAND ...`` (:mod:`.main`). Each room registers its own subcommands
with a ``register(add)`` function; this package only lists them."""
