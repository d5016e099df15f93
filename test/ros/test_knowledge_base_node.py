"""The knowledge_base node as a real process: other writers' changes, refusals, crash and restart."""

from __future__ import annotations

import random
import threading
import time
import uuid

import pytest

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge import Change, PddlObject, PddlType, Predicate, Proposition, Provenance
from merlin2_sailor.ros.stores import open_store

pytestmark = pytest.mark.ros

DECLARATIONS = [
    Change.save(PddlType("cup")),
    Change.save(Predicate("seen", ("cup",))),
]


#: How long a (re)started node's services may take to be discovered on a loaded machine.
DISCOVERY_SECONDS = 20.0


def wait_until(condition, seconds: float) -> bool:
    """Poll ``condition`` until it holds or ``seconds`` pass; the caller asserts what it needs."""
    deadline = time.monotonic() + seconds
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.02)
    return condition()


def start_knowledge_base(node_process, namespace: str, store: str):
    return node_process("knowledge_base", "--ros-args", "-r", f"__ns:={namespace}", "-p", f"store:={store}")


def test_a_client_hears_other_writers_and_refusals_leave_the_node_running(node_process) -> None:
    namespace = f"/kb_{uuid.uuid4().hex[:8]}"
    process = start_knowledge_base(node_process, namespace, "memory")
    writer, listener = open_store(f"ros://{namespace}"), open_store(f"ros://{namespace}")
    try:
        heard: list = []
        listener.subscribe(heard.append)
        # The change topic is volatile, like any event stream: a batch published before the node's
        # publisher has matched the listener is lost. Graph counts only say what each client sees,
        # not what the node's publisher has matched, so prove the stream live with probe types,
        # each a new change, until the listener hears one.
        deadline = time.monotonic() + DISCOVERY_SECONDS
        probes = 0
        while not heard and time.monotonic() < deadline:
            probes += 1
            writer.apply([Change.save(PddlType(f"probe_{probes}"))])
            wait_until(lambda: bool(heard), seconds=0.5)
        assert heard, f"no change batch heard within {DISCOVERY_SECONDS} s ({probes} probes)"
        wait_until(lambda: len(heard) >= probes, seconds=2.0)  # late echoes of earlier probes
        heard.clear()
        writer.apply(DECLARATIONS)
        writer.apply([Change.save(PddlObject("cup_1", "cup")),
                      Change.save(Proposition("seen", ("cup_1",), provenance=Provenance.PERCEIVED))])
        wait_until(lambda: len(heard) >= 2, seconds=10.0)
        assert [len(batch) for batch in heard] == [2, 2], heard
        assert listener.propositions_about("cup_1") == (
            Proposition("seen", ("cup_1",), provenance=Provenance.PERCEIVED),)

        with pytest.raises(KnowledgeError, match="seen"):  # wrong arity: refused with the reason
            writer.apply([Change.save(Proposition("seen", ("cup_1", "cup_1")))])
        assert writer.objects.get("cup_1") == PddlObject("cup_1", "cup")  # still answering
    finally:
        writer.close()
        listener.close()
    assert process.stop() == 0, process.text
    assert "write refused" in process.text


def test_an_unreachable_knowledge_base_is_a_clear_error_not_a_hang() -> None:
    with open_store(f"ros:///nobody_{uuid.uuid4().hex[:8]}") as store:
        store._timeout = 0.5  # noqa: SLF001 - keep the test short
        started = time.monotonic()
        with pytest.raises(KnowledgeError, match="is the knowledge_base node running"):
            store.objects.get_all()
        assert time.monotonic() - started < 5.0


def test_killed_at_random_moments_the_node_loses_no_acknowledged_write(tmp_path, node_process) -> None:
    """Symbols come from the writer (the anchoring node owns the counter), never from this node."""
    namespace = f"/kb_{uuid.uuid4().hex[:8]}"
    store = f"sqlite://{tmp_path / 'knowledge.db'}"
    randomness = random.Random(7)
    acknowledged: list[str] = []  # symbols whose object and fact the node confirmed
    symbols: list[str] = []  # every symbol the writer tried to store
    client = open_store(f"ros://{namespace}")
    try:
        for _round in range(3):
            process = start_knowledge_base(node_process, namespace, store)
            # A restarted node's services can take seconds to be discovered on a loaded machine:
            # wait for it as long as discovery may take, then keep calls short while it gets killed.
            client._timeout = DISCOVERY_SECONDS  # noqa: SLF001
            client.apply(DECLARATIONS)
            client._timeout = 3.0  # noqa: SLF001 - a killed node must not stall the test for long
            killer = threading.Timer(randomness.uniform(0.5, 1.5), process.process.kill)
            killer.start()
            while process.process.poll() is None:
                try:
                    symbol = f"cup_{len(symbols) + 1}"
                    symbols.append(symbol)
                    client.apply([Change.save(PddlObject(symbol, "cup")),
                                  Change.save(Proposition("seen", (symbol,)))])
                    acknowledged.append(symbol)
                except KnowledgeError:
                    break  # killed in the middle of a call: that write is not acknowledged
            killer.join()
            process.stop()
        survivor = start_knowledge_base(node_process, namespace, store)
        client._timeout = DISCOVERY_SECONDS  # noqa: SLF001
        stored_objects = {item.name for item in client.objects.get_all()}
        stored_facts = [fact.objects[0] for fact in client.propositions.get_all()]
    finally:
        client.close()
    assert survivor.stop() == 0, survivor.text
    assert len(acknowledged) >= 3
    assert set(acknowledged) <= stored_objects  # nothing acknowledged is lost
    assert stored_objects <= set(symbols)  # nothing appears that was never asked for
    assert len(stored_facts) == len(set(stored_facts)) == len(stored_objects)  # no duplicate, no orphan
    assert set(stored_facts) == stored_objects  # every stored object came with its fact: batches are whole


def test_beside_kants_node_in_one_namespace_it_says_so_and_stops(start_kant_node, node_process) -> None:
    """KANT's node serves get_types, update_type, ... with kant_msgs types; in the same namespace the
    two would answer each other's clients. The SAILOR node names the clash and exits 2."""
    namespace = f"/clash_{uuid.uuid4().hex[:8]}"
    start_kant_node(namespace)
    process = node_process("knowledge_base", "--ros-args", "-r", f"__ns:={namespace}")
    process.process.wait(timeout=30.0)
    assert process.stop() == 2, process.text
    assert f"{namespace}/get_types is also served by {namespace}/knowledge_base_node as kant_msgs/srv/" in process.text
    assert "run this node in a namespace of its own" in process.text and "Traceback" not in process.text
