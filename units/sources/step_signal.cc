namespace linesim::sources {}
