"""What the literature says of each plant-library crop: the published figures its recipe
(:mod:`davis_ag.scene.library_crops`) is checked against on docs/crops.md, with their sources."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Literature:
    """Published figures a crop's recipe is checked against (docs/crops.md), quoted as found: a
    figure the sources do not give is ``-``, never an estimate of ours.

    Attributes:
        fruit_per_plant: Fruit a plant of the library's size bears.
        fruit_size: Fruit size (length, width; a grape cluster's berries).
        plant_height: Plant height.
        source: The citations.
    """

    fruit_per_plant: str
    fruit_size: str
    plant_height: str
    source: str


LITERATURE: dict[str, Literature] = {
    "apple": Literature(
        "under 0.5-1 bushel (over-cropping at the third leaf)",
        "-",
        "3-4.9 m (semi-dwarf)",
        "MSU Extension (http://www.canr.msu.edu/news/manage_crop_load_of_young_tall_spindle_apple_plantings); "
        "McKay Nursery (https://www.mckaynursery.com/online-plants/fruit-trees-shrubs/apples-trees/semi-dwarf.html)",
    ),
    "apple-wall": Literature(
        "15-20 in the second year",
        "-",
        "about 12 ft, at most 3 ft deep",
        "Robinson 2007 (https://fruitgrowersnews.com/article/the-tall-spindle-system-apple-orchard-design-for-the-future/); "
        "http://read.dmtmag.com/i/123862-may-1/24",
    ),
    "almond": Literature(
        "a first crop of 'one or two nuts up to a hatful'",
        "-",
        "-",
        "https://bitlit.ru/chapter/en/r-h-taylor/the-almond-in-california/yields",
    ),
    "olive": Literature(
        "1-2 fruit per fruiting inflorescence",
        "-",
        "2.5-3 m (hedgerow, final)",
        "Lavee et al. 1996 (https://c.coek.info/pdf-the-floral-biology-of-the-olive-effect-of-flower-number-"
        "type-and-distribution-on.html); http://www.agromillora-ca.com/products/high-density-requirements/",
    ),
    "pistachio": Literature(
        "bearing from year 5-8; a mature tree ~1,000+",
        "15-20 mm long",
        "-",
        "https://wikifarmer.com/library/en/article/pistachio-tree-harvest-and-yield; http://aryafirm.com/index.php/pistachio/",
    ),
    "walnut": Literature(
        "bearing from about year 5",
        "28-32 mm in the shell, more in the husk",
        "-",
        "http://chandlerwalnutsapling.com/chandler-walnut-sapling.php; http://foodsource.us/nuts/walnuts/",
    ),
    "capsicum": Literature(
        "2-4 set per flush, later flowers abort",
        "up to 4 in long, 3-3.5 in broad",
        "-",
        "https://www.ingreenhouses.com/young-fruits-pull-so-hard-flowers-above-abort/; "
        "https://hort.purdue.edu/newcrop/Crops/Peppers%5BBell%5D.html",
    ),
    "cherry-tomato": Literature(
        "up to about 100",
        "1-3 cm",
        "-",
        "https://simple.wikipedia.org/wiki/Cherry_tomato; https://tomato-daily.blogspot.com/2008/06/trusses-clusters.html",
    ),
    "vsp-vine": Literature(
        "12-80 clusters",
        "70-100 berries a cluster",
        "-",
        "https://biologyinsights.com/how-many-grapes-grow-on-a-vine",
    ),
    "wye-vine": Literature(
        "12-80 clusters",
        "70-100 berries a cluster",
        "-",
        "https://biologyinsights.com/how-many-grapes-grow-on-a-vine",
    ),
}
