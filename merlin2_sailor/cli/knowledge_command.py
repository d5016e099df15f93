"""``sailor knowledge``: look into a knowledge base (the running node's, or a store's file).

``show`` prints what the planner will see as readable tables, with where each fact came from;
``pddl`` prints the domain and problem text the planner receives.
"""

from __future__ import annotations

import argparse

from merlin2_sailor.knowledge import ItemKind, KnowledgeBase
from merlin2_sailor.knowledge.pddl_writer import domain_from_store, problem_from_store
from merlin2_sailor.ros.stores import open_store

DEFAULT_STORE = "ros:///merlin2"


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "knowledge", help="show a knowledge base as tables or as PDDL",
        description="Read a knowledge base: the knowledge_base node's (default ros:///merlin2) "
                    "or a store directly (sqlite:///path.db, mongodb://host:port/db).",
    )
    parser.add_argument("view", choices=("show", "pddl"),
                        help="show: tables of objects and facts; pddl: the domain and problem text")
    parser.add_argument("--store", default=DEFAULT_STORE, metavar="LOCATION",
                        help=f"knowledge base location (default {DEFAULT_STORE})")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    with open_store(arguments.store) as store:
        print(render_tables(store) if arguments.view == "show" else render_pddl(store))
    return 0


def render_tables(store: KnowledgeBase) -> str:
    objects = sorted(store.get_all(ItemKind.OBJECT), key=lambda item: (item.type, item.name))
    propositions = sorted(store.get_all(ItemKind.PROPOSITION), key=lambda item: (item.is_goal, str(item)))
    lines = [f"objects ({len(objects)})"]
    lines += [f"  {item.name:<24} {item.type}" for item in objects]
    facts = [item for item in propositions if not item.is_goal]
    goals = [item for item in propositions if item.is_goal]
    lines.append(f"facts ({len(facts)})")
    lines += [f"  {str(item):<48} {item.provenance.value}" for item in facts]
    lines.append(f"goals ({len(goals)})")
    lines += [f"  {item}" for item in goals]
    return "\n".join(lines)


def render_pddl(store: KnowledgeBase) -> str:
    return f"{domain_from_store(store)}\n\n{problem_from_store(store)}"
