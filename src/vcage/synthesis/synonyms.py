"""Synonyms for retrieval, kept as data: each canonical catalog word with the words people use for it.

A query word (after stemming) that appears among a group's variants adds the group's canonical
words to the query. Canonical words are words of the catalog's own documents (type names, tags,
categories, descriptions). Topical groups (``breakfast``, ``drink``) expand a theme to the catalog
words it suggests; they are weaker hints and are weighted below a word's own synonyms.
"""

from __future__ import annotations

# canonical words (space separated) <- variants (space separated; multi-word variants joined by _)
SYNONYMS: tuple[tuple[str, str], ...] = (
    ("mug", "mug mugs coffee_mug cuppa stein"),
    ("cup", "cup cups tumbler beaker teacup"),
    ("bottle", "bottle bottles flask canteen water_bottle"),
    ("plate", "plate plates dish platter saucer dinnerware"),
    ("bowl", "bowl bowls basin porridge soup"),
    ("basket", "basket baskets hamper wicker"),
    ("box", "box boxes carton crate cardboard"),
    ("bread", "bread loaf loaves baguette toast bun roll"),
    ("can soda", "can cans tin soda cola pop fizzy"),
    ("cereal box", "cereal cornflakes muesli granola"),
    ("jar jam", "jar jam jelly preserve marmalade honey"),
    ("apple", "apple apples"),
    ("banana", "banana bananas plantain"),
    ("orange", "orange oranges citrus tangerine mandarin clementine"),
    ("coaster", "coaster coasters drink_mat beer_mat"),
    ("remote control", "remote clicker controller tv_remote"),
    ("phone smartphone", "phone smartphone cellphone cell_phone mobile iphone handset"),
    ("mouse computer", "mouse mice"),
    ("mouse pad", "mousepad mouse_pad mousemat"),
    ("marker", "marker markers felt_tip highlighter sharpie"),
    ("pen holder", "pen_holder pencil_cup pen_pot pencil_holder"),
    ("pen", "pen pens pencil pencils"),
    ("glue stick", "glue gluestick adhesive"),
    ("tape", "tape sellotape scotch_tape duct"),
    ("stapler", "stapler staples"),
    ("stamp seal", "stamp rubber_stamp seal"),
    ("stamp pad", "ink_pad stamp_pad inkpad"),
    ("book", "book books novel textbook hardback hardcover notebook"),
    ("tissue box", "tissue tissues kleenex"),
    ("sponge", "sponge sponges scrubber scourer"),
    ("soap", "soap bar_of_soap"),
    ("pot", "pot pots saucepan casserole stockpot cooking_pot"),
    ("tray", "tray trays serving_tray"),
    ("alarm clock", "clock alarm timer"),
    ("bell", "bell bells ringer chime doorbell"),
    ("switch", "switch light_switch toggle rocker"),
    ("block", "block blocks brick bricks"),
    ("dice", "dice die"),
    ("rubik cube", "rubik rubiks puzzle_cube speedcube puzzle"),
    ("qr board", "qr qrcode barcode sign signboard placard"),
    ("tennis ball", "ball balls tennis"),
    ("toy car", "car cars vehicle truck"),
    ("playing card", "card cards playing_card"),
    ("stand pedestal", "pedestal plinth riser display_stand"),
    ("phone stand", "phone_stand dock cradle charging_stand"),
)

# themes -> catalog words they suggest (weaker: the query says what kind of scene, not which object)
TOPICS: tuple[tuple[str, str], ...] = (
    ("bread cereal jam cup bowl plate", "breakfast brunch morning"),
    ("cup mug bottle can drink", "drink drinks beverage tea coffee thirsty"),
    ("apple banana orange fruit", "fruit fruits snack healthy"),
    ("plate bowl cup tray tableware", "dinner lunch supper meal tableware"),
    ("office stapler marker pen tape", "office paperwork stationery desk"),
    ("toy block dice ball car", "toys play playroom child kid"),
    ("kitchen sponge soap pot", "kitchen wash washing dishes sink"),
)

# words that say nothing about which object is meant
GENERIC = frozenset("""
object objects thing things item items stuff something anything please put place move set
arrange organize organise tidy clean get make bring take give find want need some any small big
large little one two three table tabletop scene top left right front behind near next
pair pairs piece pieces bunch couple
""".split())  # noqa: SIM905

# nouns of amount: in "a pack of cards" the object is what follows "of"
QUANTITIES = frozenset("pack packet stack pile heap handful".split())  # noqa: SIM905
