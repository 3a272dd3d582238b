"""The views of the explorer page: one small view per sidebar tab and one for the results.

Each view builds its widgets over the session's state objects and knows how to refresh
them; :mod:`explorer.app` assembles the page from them in one place (``SIDEBAR_VIEWS``).
"""
