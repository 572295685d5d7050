"""ReadTextFileAsString: a text file's content as a string."""

from __future__ import annotations

from kinema.behaviors import AsyncBehavior, PortInfo, input_port, output_port

from ..messages.ports import fails_on_bad_input, port_error, read_input
from .locations import RELATIVE_READ, file_to_read

MAX_BYTES = 10 * 1024 * 1024


class ReadTextFileAsString(AsyncBehavior):
    """Reads a UTF-8 text file (relative paths: the objectives folder) into ``string_file_contents``."""

    subcategory = "File Management"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("text_filename", str, "", f"The file; {RELATIVE_READ}."),
            output_port("string_file_contents", str, "{string_file_contents}", "Its content."),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        path = file_to_read(self, "text_filename", str(read_input(self, "text_filename")))
        if path.stat().st_size > MAX_BYTES:
            raise port_error(self, "text_filename", f"file {path} is larger than {MAX_BYTES} bytes", "")
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as error:
            raise port_error(
                self, "text_filename", f"file {path} cannot be read as text: {error}", ""
            ) from None
        self.set_output("string_file_contents", text)
        return True
