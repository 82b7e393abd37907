"""Nastran stick models and flutter decks read into a wing file and a flutter scenario
(pyNastran parses the deck; :mod:`.importer` is the entry point)."""
