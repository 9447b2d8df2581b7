"""The certificate of every result (ISO/IEC 17025:2017 7.8): the one page style of the HTML
reports (:mod:`.page`), the PDF certificate (:mod:`.pdf`), the uncertainty budget of a
reported quantity (:mod:`.budget`), and the identification stamped into a command's written
outputs (:mod:`.stamp`).  Part of the ``base`` room: it imports nothing of volerr's
capabilities; results hand it their JSON document, rows and figures."""
