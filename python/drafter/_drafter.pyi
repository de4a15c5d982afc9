# Type hints of the native module (python/src/lib.rs); the documented API is drafter/__init__.py.
from typing import Any, Callable, List, Optional, Tuple

__version__: str
BUILD_ID: str

class DrafterError(Exception): ...
class InputError(DrafterError): ...
class IoError(DrafterError, OSError): ...
class InternalError(DrafterError): ...

def bake(
    *,
    path: Optional[str] = None,
    data: Optional[bytes] = None,
    name: Optional[str] = None,
    config_toml: Optional[str] = None,
    config_json: Optional[str] = None,
    threads: Optional[int] = None,
    max_triangles: Optional[int] = None,
) -> bytes: ...
def bake_file(
    input: str,
    output: str,
    *,
    root: Optional[str] = None,
    config_toml: Optional[str] = None,
    config_json: Optional[str] = None,
    cache: Optional[str] = None,
    cache_max: Optional[int] = None,
    threads: Optional[int] = None,
    max_triangles: Optional[int] = None,
) -> str: ...
def bake_many(
    inputs: List[str],
    out_dir: str,
    *,
    manifests: List[str] = ...,
    config_toml: Optional[str] = None,
    config_json: Optional[str] = None,
    cache: Optional[str] = None,
    cache_max: Optional[int] = None,
    memory: Optional[int] = None,
    jobs: Optional[int] = None,
    max_triangles: Optional[int] = None,
    progress: Optional[Callable[[str, int, int], Any]] = None,
) -> Tuple[str, Optional[BaseException]]: ...
def draw_file(
    input: str,
    output: str,
    *,
    spec_json: Optional[str] = None,
    cache: Optional[str] = None,
    cache_max: Optional[int] = None,
    threads: Optional[int] = None,
    max_triangles: Optional[int] = None,
) -> str: ...
def draw_many(
    inputs: List[str],
    out_dir: str,
    *,
    manifests: List[str] = ...,
    formats: List[str] = ...,
    spec_json: Optional[str] = None,
    cache: Optional[str] = None,
    cache_max: Optional[int] = None,
    memory: Optional[int] = None,
    jobs: Optional[int] = None,
    max_triangles: Optional[int] = None,
    progress: Optional[Callable[[str, int, int], Any]] = None,
) -> Tuple[str, Optional[BaseException]]: ...
def discover(inputs: List[str], manifests: List[str] = ..., skip: Optional[str] = None) -> List[Tuple[str, str]]: ...
def inspect(
    *, path: Optional[str] = None, data: Optional[bytes] = None, name: Optional[str] = None, max_triangles: Optional[int] = None
) -> str: ...
def cache(dir: str, action: str, size: Optional[int] = None) -> str: ...
