"""What is particular to each store: opening by name, databases, failures and missing libraries."""

import enum
import sqlite3
import sys
import time
from types import SimpleNamespace

import pytest

from merlin2_sailor.errors import ConfigurationError, DependencyError, KnowledgeError
from merlin2_sailor.knowledge import (
    Change,
    ItemKind,
    Operation,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    Provenance,
    open_store,
)
from merlin2_sailor.knowledge.kant_store import KantStore
from merlin2_sailor.knowledge.memory_store import MemoryStore
from merlin2_sailor.knowledge.mongo_store import MongoStore
from merlin2_sailor.knowledge.sqlite_store import SqliteStore
from merlin2_sailor.knowledge.store import KnowledgeBase
from merlin2_sailor.knowledge.stores import STORES, scheme_of
from merlin2_sailor.ros import stores as ros_stores

from .kant_stand_in import KANT_DTO, InMemoryDaoFactory

SEEN = Predicate("seen", ("object",))


class TestOpenStore:
    def test_memory_is_the_default(self):
        with open_store() as store:
            assert isinstance(store, MemoryStore)

    def test_sqlite_path_follows_the_scheme(self, tmp_path):
        path = tmp_path / "kb.db"
        with open_store(f"sqlite://{path}") as store:
            assert isinstance(store, SqliteStore)
            store.objects.save(PddlObject("cup_1", "cup"))
        assert path.exists()
        with open_store("sqlite://:memory:") as store:
            assert store.objects.get_all() == ()

    @pytest.mark.parametrize("location", ["", "redis://localhost", "sqlite:", "sqlite://", "mem"])
    def test_unknown_locations_are_configuration_errors(self, location):
        with pytest.raises(ConfigurationError, match="sqlite"):
            open_store(location)

    def test_mongodb_uri(self, mongo_server):
        with open_store(f"{mongo_server}/factory") as store:
            assert isinstance(store, MongoStore)

    @pytest.mark.parametrize(
        ("location", "scheme"),
        [("memory", "memory"), ("sqlite:///a/b.db", "sqlite"), ("mongodb+srv://h/d", "mongodb+srv"),
         ("ros:///merlin2", "ros"), ("", ""), ("sqlite:", "sqlite:")],
    )
    def test_the_scheme_is_what_comes_before_the_separator(self, location, scheme):
        assert scheme_of(location) == scheme

    def test_an_unknown_scheme_names_the_known_ones_and_the_forms(self):
        with pytest.raises(ConfigurationError) as caught:
            open_store("redis://localhost")
        message = str(caught.value)
        assert "'redis'" in message and "kant+mongodb, memory, mongodb, mongodb+srv, sqlite" in message
        assert "sqlite:///absolute/path.db" in message

    def test_every_table_entry_is_a_store_opened_by_location(self):
        for name in STORES.names:
            store_class = STORES.load(name)
            assert issubclass(store_class, KnowledgeBase), name
            assert "from_location" in vars(store_class), f"{name}: {store_class.__name__} has no from_location"

    def test_the_core_table_has_no_ros_store_and_says_where_it_is(self):
        assert "ros" not in STORES
        with pytest.raises(ConfigurationError, match=r"merlin2_sailor\.ros\.stores"):
            open_store("ros:///merlin2")

    def test_the_ros_layer_adds_its_two_nodes_and_opens_the_core_stores_alike(self, tmp_path):
        assert set(ros_stores.STORES.names) == {*STORES.names, "ros", "kant+ros"}
        assert ros_stores.STORES.entries["ros"].endswith(":RemoteKnowledgeBase")
        assert ros_stores.STORES.entries["kant+ros"].endswith(":KantRosStore")
        with ros_stores.open_store(f"sqlite://{tmp_path / 'kb.db'}") as store:
            assert isinstance(store, SqliteStore)

    def test_the_timeout_reaches_a_store_with_a_server(self):
        started = time.monotonic()
        with pytest.raises(KnowledgeError, match="cannot use MongoDB"):
            open_store("mongodb://127.0.0.1:9/kb", timeout=0.2)
        assert time.monotonic() - started < 3.0  # the default waits 5 s


class TestKantByLocation:
    """``kant+mongodb://`` opens KANT's MongoDB DAO family, KANT itself imported only then."""

    @pytest.fixture
    def fake_kant(self, monkeypatch):
        created = []

        class DaoFamilies(enum.Enum):
            ROS2 = 0
            MONGO = 1

        class DaoFactoryMethod:
            def create_dao_factory(self, family, **kwargs):
                factory = InMemoryDaoFactory()
                created.append((family, kwargs, factory))
                return factory

        dao_factory = SimpleNamespace(DaoFamilies=DaoFamilies, DaoFactoryMethod=DaoFactoryMethod)
        monkeypatch.setitem(sys.modules, "kant_dao", SimpleNamespace(dao_factory=dao_factory))
        monkeypatch.setitem(sys.modules, "kant_dao.dao_factory", dao_factory)
        monkeypatch.setitem(sys.modules, "kant_dto", KANT_DTO)
        return created

    def test_the_location_names_kants_mongodb_family_and_its_uri(self, fake_kant):
        with open_store("kant+mongodb://db.local:27017/kant") as store:
            assert isinstance(store, KantStore)
            store.objects.save(PddlObject("cup_1", "cup"))
        ((family, arguments, factory),) = fake_kant
        assert family.name == "MONGO" and arguments == {"uri": "mongodb://db.local:27017/kant"}
        assert set(factory.objects.items) == {"cup_1"}

    def test_a_location_without_a_database_is_a_configuration_error(self, fake_kant):
        with pytest.raises(ConfigurationError, match="kant\\+mongodb://host:port/database"):
            open_store("kant+mongodb://")
        assert fake_kant == []

    def test_without_kant_it_says_how_to_get_it(self, monkeypatch):
        monkeypatch.setitem(sys.modules, "kant_dao", None)
        monkeypatch.setitem(sys.modules, "kant_dao.dao_factory", None)
        with pytest.raises(DependencyError, match="build KANT in your ROS 2 workspace"):
            open_store("kant+mongodb://localhost:27017/kant")


class TestSqliteStore:
    def test_uses_write_ahead_logging(self, tmp_path):
        with SqliteStore(tmp_path / "kb.db") as store:
            store.objects.save(PddlObject("cup_1", "cup"))
        connection = sqlite3.connect(tmp_path / "kb.db")
        assert connection.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        rows = connection.execute("SELECT key FROM objects").fetchall()
        assert rows == [("cup_1",)]
        connection.close()

    def test_a_failed_write_leaves_memory_and_file_unchanged(self, tmp_path):
        path = tmp_path / "kb.db"
        with SqliteStore(path) as store:
            store.apply([Change.save(PddlObject("cup_1", "cup")), Change.save(SEEN)])
            vandal = sqlite3.connect(path)
            vandal.execute("DROP TABLE propositions")
            vandal.commit()
            vandal.close()
            with pytest.raises(KnowledgeError, match="could not write"):
                store.apply(
                    [
                        Change.save(PddlObject("cup_2", "cup")),
                        Change.delete_key(ItemKind.OBJECT, "cup_1"),
                        Change.save(Proposition("seen", ("cup_2",))),
                    ]
                )
            assert {o.name for o in store.objects.get_all()} == {"cup_1"}
            assert store.propositions.get_all() == ()
        connection = sqlite3.connect(path)
        assert connection.execute("SELECT key FROM objects").fetchall() == [("cup_1",)]
        connection.close()

    def test_refuses_a_newer_schema(self, tmp_path):
        path = tmp_path / "kb.db"
        connection = sqlite3.connect(path)
        connection.execute("PRAGMA user_version=99")
        connection.close()
        with pytest.raises(KnowledgeError, match="schema 99"):
            SqliteStore(path)

    def test_an_unusable_path_is_a_knowledge_error(self, tmp_path):
        blocker = tmp_path / "a_file"
        blocker.write_text("not a folder")
        with pytest.raises(KnowledgeError, match="cannot open"):
            SqliteStore(blocker / "kb.db")

    def test_missing_folders_are_created(self, tmp_path):
        path = tmp_path / "new" / "folders" / "kb.db"
        with SqliteStore(path) as store:
            store.objects.save(PddlObject("cup_1", "cup"))
        assert path.is_file()


class TestMongoStore:
    def test_documents_are_keyed_readably(self, mongo_server):
        import pymongo

        uri = f"{mongo_server}/readable"
        with MongoStore(uri) as store:
            store.objects.save(PddlObject("cup_1", "cup"))
            store.apply(
                [
                    Change.save(PddlType("wp")),
                    Change.save(PddlObject("kitchen", "wp")),
                ]
            )
        client = pymongo.MongoClient(uri)
        try:
            names = sorted(d["_id"] for d in client.get_default_database()["objects"].find())
        finally:
            client.close()
        assert names == ["cup_1", "kitchen"]

    def test_an_unreachable_server_is_a_knowledge_error(self):
        with pytest.raises(KnowledgeError, match="cannot use MongoDB"):
            MongoStore("mongodb://127.0.0.1:9/kb", timeout_seconds=0.2)

    def test_a_missing_pymongo_is_a_dependency_error(self, monkeypatch):
        monkeypatch.setitem(sys.modules, "pymongo", None)
        with pytest.raises(DependencyError, match="pip install pymongo"):
            open_store("mongodb://127.0.0.1:27017/kb")


class TestChange:
    def test_a_save_needs_an_item(self):
        with pytest.raises(KnowledgeError, match=r"Change\.save"):
            Change(Operation.SAVE, ItemKind.TYPE, "cup")

    def test_kind_and_key_must_match_the_item(self):
        with pytest.raises(KnowledgeError, match="carries"):
            Change(Operation.SAVE, ItemKind.OBJECT, "cup", PddlType("cup"))

    def test_non_items_are_refused(self, memory_store):
        with pytest.raises(KnowledgeError, match="not a knowledge item"):
            Change.save("cup_1")  # type: ignore[arg-type]
        with pytest.raises(KnowledgeError, match="not a Change"):
            memory_store.apply([PddlObject("cup_1", "cup")])  # type: ignore[list-item]

    def test_provenance_must_be_the_enum(self):
        with pytest.raises(KnowledgeError, match="Provenance"):
            Proposition("seen", ("cup_1",), provenance="perceived")  # type: ignore[arg-type]
        assert Proposition("seen", ("cup_1",), provenance=Provenance.PERCEIVED).key == (
            "seen",
            ("cup_1",),
            False,
        )
