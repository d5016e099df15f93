"""``sailor knowledge`` on a SQLite knowledge base written by another process."""

from __future__ import annotations

from merlin2_sailor.cli.main import main
from merlin2_sailor.knowledge import Change, PddlObject, PddlType, Predicate, Proposition, Provenance, open_store


def test_show_and_pddl_print_what_the_store_holds(tmp_path, capsys) -> None:
    location = f"sqlite://{tmp_path / 'kb.db'}"
    with open_store(location) as store:
        store.apply([Change.save(item) for item in (
            PddlType("cup"), PddlType("wp"), PddlObject("cup_3", "cup"), PddlObject("kitchen", "wp"),
            Predicate("object_at", ("cup", "wp")),
            Proposition("object_at", ("cup_3", "kitchen"), provenance=Provenance.PERCEIVED),
            Proposition("object_at", ("cup_3", "kitchen"), is_goal=True),
        )])
    assert main(["knowledge", "show", "--store", location]) == 0
    shown = capsys.readouterr().out
    assert "cup_3" in shown and "object_at(cup_3, kitchen)" in shown and "perceived" in shown
    assert "goals (1)" in shown
    assert main(["knowledge", "pddl", "--store", location]) == 0
    pddl = capsys.readouterr().out
    assert "(define (domain" in pddl and "(object_at cup_3 kitchen)" in pddl


def test_an_unknown_store_is_one_clear_line(capsys) -> None:
    assert main(["knowledge", "show", "--store", "redis://somewhere"]) == 2
    assert "unknown knowledge store" in capsys.readouterr().err
