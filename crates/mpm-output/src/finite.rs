//! A serde serialiser that only looks for NaN and infinity.
//!
//! `serde_json` silently writes a non-finite float as `null`; running this
//! check first turns that into an error naming the field, e.g.
//! `cases[2].error_l2`.

use std::fmt;

use serde::Serialize;
use serde::ser;

/// The first non-finite float in `value`, with the path to it, or `None`.
///
/// Errors that `value`'s own `Serialize` implementation raises are not
/// reported here: the real serialiser will meet them again and report them.
pub(crate) fn find_non_finite<T: Serialize + ?Sized>(value: &T) -> Option<(String, f64)> {
    let mut checker = Checker { path: Vec::new() };
    match value.serialize(&mut checker) {
        Err(Stop::Found { path, value }) => Some((path, value)),
        Ok(()) | Err(Stop::Other(_)) => None,
    }
}

/// One step of the path from the root to a value.
enum Segment {
    Field(&'static str),
    Key(String),
    Index(usize),
}

struct Checker {
    path: Vec<Segment>,
}

impl Checker {
    fn path_string(&self) -> String {
        let mut s = String::new();
        for seg in &self.path {
            match seg {
                Segment::Field(f) => push_dotted(&mut s, f),
                Segment::Key(k) => push_dotted(&mut s, k),
                Segment::Index(i) => s.push_str(&format!("[{i}]")),
            }
        }
        if s.is_empty() { "(root)".to_owned() } else { s }
    }

    fn float(&self, x: f64) -> Result<(), Stop> {
        if x.is_finite() {
            Ok(())
        } else {
            Err(Stop::Found {
                path: self.path_string(),
                value: x,
            })
        }
    }

    fn nested<T: Serialize + ?Sized>(&mut self, seg: Segment, value: &T) -> Result<(), Stop> {
        self.path.push(seg);
        let r = value.serialize(&mut *self);
        self.path.pop();
        r
    }
}

fn push_dotted(s: &mut String, name: &str) {
    if !s.is_empty() {
        s.push('.');
    }
    s.push_str(name);
}

/// Why the walk stopped.
#[derive(Debug)]
enum Stop {
    Found { path: String, value: f64 },
    Other(String),
}

impl fmt::Display for Stop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Found { path, value } => write!(f, "{path} = {value}"),
            Self::Other(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for Stop {}

impl ser::Error for Stop {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Self::Other(msg.to_string())
    }
}

/// Walks the elements of a sequence, map or struct.
struct Compound<'c> {
    checker: &'c mut Checker,
    index: usize,
    key: Option<String>,
}

macro_rules! ok_scalars {
    ($($method:ident: $ty:ty),* $(,)?) => {
        $(fn $method(self, _: $ty) -> Result<(), Stop> { Ok(()) })*
    };
}

impl<'c> ser::Serializer for &'c mut Checker {
    type Ok = ();
    type Error = Stop;
    type SerializeSeq = Compound<'c>;
    type SerializeTuple = Compound<'c>;
    type SerializeTupleStruct = Compound<'c>;
    type SerializeTupleVariant = Compound<'c>;
    type SerializeMap = Compound<'c>;
    type SerializeStruct = Compound<'c>;
    type SerializeStructVariant = Compound<'c>;

    ok_scalars!(
        serialize_bool: bool, serialize_i8: i8, serialize_i16: i16, serialize_i32: i32,
        serialize_i64: i64, serialize_i128: i128, serialize_u8: u8, serialize_u16: u16,
        serialize_u32: u32, serialize_u64: u64, serialize_u128: u128, serialize_char: char,
        serialize_str: &str, serialize_bytes: &[u8], serialize_unit_struct: &'static str,
    );

    fn serialize_f32(self, v: f32) -> Result<(), Stop> {
        self.float(f64::from(v))
    }
    fn serialize_f64(self, v: f64) -> Result<(), Stop> {
        self.float(v)
    }
    fn serialize_none(self) -> Result<(), Stop> {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<(), Stop> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Result<(), Stop> {
        Ok(())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, _: &'static str) -> Result<(), Stop> {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), Stop> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), Stop> {
        self.nested(Segment::Field(variant), value)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Compound<'c>, Stop> {
        Ok(Compound::new(self))
    }
    fn serialize_tuple(self, _: usize) -> Result<Compound<'c>, Stop> {
        Ok(Compound::new(self))
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Compound<'c>, Stop> {
        Ok(Compound::new(self))
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Compound<'c>, Stop> {
        self.path.push(Segment::Field(variant));
        Ok(Compound::new(self))
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Compound<'c>, Stop> {
        Ok(Compound::new(self))
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Compound<'c>, Stop> {
        Ok(Compound::new(self))
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Compound<'c>, Stop> {
        self.path.push(Segment::Field(variant));
        Ok(Compound::new(self))
    }
}

impl<'c> Compound<'c> {
    fn new(checker: &'c mut Checker) -> Self {
        Self {
            checker,
            index: 0,
            key: None,
        }
    }

    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
        let i = self.index;
        self.index += 1;
        self.checker.nested(Segment::Index(i), value)
    }

    /// Ends a variant, whose name was pushed when it began.
    fn end_variant(self) -> Result<(), Stop> {
        self.checker.path.pop();
        Ok(())
    }
}

impl ser::SerializeSeq for Compound<'_> {
    type Ok = ();
    type Error = Stop;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
        self.element(value)
    }
    fn end(self) -> Result<(), Stop> {
        Ok(())
    }
}

impl ser::SerializeTuple for Compound<'_> {
    type Ok = ();
    type Error = Stop;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
        self.element(value)
    }
    fn end(self) -> Result<(), Stop> {
        Ok(())
    }
}

impl ser::SerializeTupleStruct for Compound<'_> {
    type Ok = ();
    type Error = Stop;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
        self.element(value)
    }
    fn end(self) -> Result<(), Stop> {
        Ok(())
    }
}

impl ser::SerializeTupleVariant for Compound<'_> {
    type Ok = ();
    type Error = Stop;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
        self.element(value)
    }
    fn end(self) -> Result<(), Stop> {
        self.end_variant()
    }
}

impl ser::SerializeMap for Compound<'_> {
    type Ok = ();
    type Error = Stop;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Stop> {
        // Keys are rarely floats, but a float key would be written too.
        key.serialize(&mut *self.checker)?;
        self.key = Some(match serde_json::to_value(key) {
            Ok(serde_json::Value::String(s)) => s,
            Ok(v) => v.to_string(),
            Err(_) => "?".to_owned(),
        });
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
        let key = self.key.take().unwrap_or_else(|| "?".to_owned());
        self.checker.nested(Segment::Key(key), value)
    }
    fn end(self) -> Result<(), Stop> {
        Ok(())
    }
}

impl ser::SerializeStruct for Compound<'_> {
    type Ok = ();
    type Error = Stop;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Stop> {
        self.checker.nested(Segment::Field(key), value)
    }
    fn end(self) -> Result<(), Stop> {
        Ok(())
    }
}

impl ser::SerializeStructVariant for Compound<'_> {
    type Ok = ();
    type Error = Stop;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Stop> {
        self.checker.nested(Segment::Field(key), value)
    }
    fn end(self) -> Result<(), Stop> {
        self.end_variant()
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use serde::Serialize;

    use super::find_non_finite;

    #[derive(Serialize)]
    struct Row {
        h: f64,
        error: f32,
    }

    #[derive(Serialize)]
    enum Outcome {
        Failed { residual: f64 },
    }

    #[derive(Serialize)]
    struct Summary {
        name: &'static str,
        rows: Vec<Row>,
        extra: BTreeMap<String, Option<f64>>,
        outcome: Option<Outcome>,
    }

    fn summary() -> Summary {
        Summary {
            name: "case",
            rows: vec![
                Row { h: 0.5, error: 0.1 },
                Row {
                    h: 0.25,
                    error: 0.02,
                },
            ],
            extra: BTreeMap::from([("rate".to_owned(), Some(2.0)), ("none".to_owned(), None)]),
            outcome: None,
        }
    }

    #[test]
    fn finite_values_pass() {
        assert_eq!(find_non_finite(&summary()), None);
    }

    #[test]
    fn paths_name_the_field() {
        let mut s = summary();
        s.rows[1].error = f32::INFINITY;
        assert_eq!(
            find_non_finite(&s),
            Some(("rows[1].error".to_owned(), f64::INFINITY))
        );

        let mut s = summary();
        s.extra.insert("rate".to_owned(), Some(f64::NEG_INFINITY));
        assert_eq!(
            find_non_finite(&s),
            Some(("extra.rate".to_owned(), f64::NEG_INFINITY))
        );

        let mut s = summary();
        s.outcome = Some(Outcome::Failed { residual: f64::NAN });
        let (path, value) = find_non_finite(&s).expect("NaN must be found");
        assert_eq!(path, "outcome.Failed.residual");
        assert!(value.is_nan());

        assert_eq!(
            find_non_finite(&f64::INFINITY),
            Some(("(root)".to_owned(), f64::INFINITY))
        );
    }
}
