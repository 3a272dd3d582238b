"""``.. cli-help:: module:function``: the ``--help`` text of a command, taken from its parser.

The function returns the :class:`argparse.ArgumentParser`; the help of each subcommand
follows the command's own, so the page can never disagree with the command.
"""

from __future__ import annotations

import argparse
import importlib
import os
from typing import Any

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective

#: The width the help is wrapped to (argparse reads COLUMNS).
HELP_COLUMNS = 88


def _help_texts(parser: argparse.ArgumentParser) -> list[str]:
    texts = [parser.format_help()]
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                texts += _help_texts(sub)
    return texts


class CliHelp(SphinxDirective):
    required_arguments = 1
    has_content = False

    def run(self) -> list[nodes.Node]:
        module_name, _, function = self.arguments[0].partition(":")
        old = os.environ.get("COLUMNS")
        os.environ["COLUMNS"] = str(HELP_COLUMNS)
        try:
            parser = getattr(importlib.import_module(module_name), function)()
            texts = _help_texts(parser)
        finally:
            if old is None:
                os.environ.pop("COLUMNS", None)
            else:
                os.environ["COLUMNS"] = old
        return [nodes.literal_block(text, text, language="text") for text in texts]


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("cli-help", CliHelp)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
