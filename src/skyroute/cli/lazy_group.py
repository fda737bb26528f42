"""A Typer group whose commands are imported when they are used.

Typer builds every command from its function's signature, so registering a command
imports its module, and with it what the command runs: ``skyroute plan`` would load
SQLAlchemy, pydantic, scipy and shapely for the commands it does not run. Here each
command is a loader (a light function that imports the command's module in its body);
the group calls it when the command is run, or listed in ``--help``.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Iterator, MutableMapping

import typer
import typer.main
from typer.core import TyperArgument, TyperGroup

# A loader returns a command function or a Typer sub-application.
Loader = Callable[[], Callable | typer.Typer]


def to_click(name: str, obj: Callable | typer.Typer):
    """The click command Typer would build for ``obj`` registered as ``name``, tidied
    (:func:`tidied`)."""
    host = typer.Typer(add_completion=False)
    if isinstance(obj, typer.Typer):
        host.add_typer(obj, name=name)
        return tidied(typer.main.get_command(host).commands[name])
    host.command(name)(obj)
    return tidied(typer.main.get_command(host))


def unwrap(text: str | None) -> str | None:
    """A docstring's paragraphs each on one line. Typer's Rich help keeps the line breaks
    of every paragraph after the first and then wraps again at the terminal's width, so a
    docstring wrapped at 88 columns showed lines broken mid-sentence. A paragraph that
    starts with ``\\b`` (click's "keep as written") is kept."""
    if not text:
        return text
    paragraphs = inspect.cleandoc(text).split("\n\n")
    return "\n\n".join(p if p.startswith("\b") else " ".join(p.split("\n"))
                       for p in paragraphs)


class PlainArgument(TyperArgument):
    """A positional argument whose usage line shows its metavar as written (``skyroute
    fly [OPTIONS] WORLD``): Typer 0.28 writes a required one in braces, ``{WORLD}``."""

    def make_metavar(self, ctx, *, usage: bool = False) -> str:
        if usage and self.required:
            var = self.metavar or (self.name or "").upper()
            return var if self.nargs == 1 else f"{var}..."
        return super().make_metavar(ctx, usage=usage)


def tidied(command):
    """``command`` and its subcommands, in place, as ``--help`` should show them: help
    paragraphs unwrapped (:func:`unwrap`), arguments named without braces
    (:class:`PlainArgument`). Every command of the group passes here, however it was
    added (:class:`LazyCommands`)."""
    command.help = unwrap(command.help)
    for param in command.params:
        if type(param) is TyperArgument:
            param.__class__ = PlainArgument  # the same object, one method overridden
    for sub in getattr(command, "commands", {}).values():
        tidied(sub)
    return command


class LazyCommands(MutableMapping):
    """The group's commands by name, the loaders' first (each built on first lookup), then
    the ones built already; in that order, whatever has been built since."""

    def __init__(self, built: MutableMapping, loaders: dict[str, Loader]):
        self._built = {name: tidied(command) for name, command in built.items()}
        self._loaders = {k: v for k, v in loaders.items() if k not in built}
        self._order = [*self._loaders, *self._built]

    def __getitem__(self, name):
        if name not in self._built:
            self._built[name] = to_click(name, self._loaders.pop(name)())
        return self._built[name]

    def __setitem__(self, name, command):
        if name not in self._order:
            self._order.append(name)
        self._loaders.pop(name, None)
        self._built[name] = tidied(command)

    def __delitem__(self, name):
        if self._loaders.pop(name, None) is None:
            del self._built[name]
        self._order.remove(name)

    def __iter__(self) -> Iterator[str]:
        return iter(list(self._order))

    def __len__(self) -> int:
        return len(self._order)


def lazy_group(loaders: dict[str, Loader]) -> type[TyperGroup]:
    """A :class:`TyperGroup` class (for ``typer.Typer(cls=...)``) that adds ``loaders``'
    commands, listed first, to the ones registered on the app."""

    class LazyGroup(TyperGroup):
        def __init__(self, **attrs):
            super().__init__(**attrs)
            self.commands = LazyCommands(self.commands, loaders)

        def list_commands(self, ctx) -> list[str]:
            return list(self.commands)

    return LazyGroup
